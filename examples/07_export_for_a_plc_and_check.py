"""07 — Cam tables for a Siemens PLC, and checking the files a colleague edited.

A SIMATIC ``TO_Cam`` takes at most 1,000 interpolation points and interpolates
linearly between them. trajgen resamples the verified schedule to that many
points, placed where they matter (the starts, stops, reversals and closest
approaches always; the rest where linear interpolation would err most), reads
the written files back and verifies them *as the controller will interpolate
them*. Then it checks the files alone, as ``trajgen check`` does, once as
written and once after one point was moved by a centimetre.
"""

import os
import tempfile
from pathlib import Path

from trajgen import Outputs, load_scenario, run
from trajgen.export.plc.check import check_profiles

here = Path(__file__).resolve().parent
scenario = load_scenario(here / "swap.toml")
# The files go to $TRAJGEN_EXAMPLE_OUTPUT if it is set (and stay there), else to a temporary
# folder that is removed when the script ends.
kept = os.environ.get("TRAJGEN_EXAMPLE_OUTPUT")
scratch = None if kept else tempfile.TemporaryDirectory(prefix="trajgen-example-")
output = Path(kept or scratch.name).resolve()
folder = output / "siemens"

# Schedule (optimal), resample for the TO_Cam, verify the tables as written, commit both files.
result = run(scenario, outputs=Outputs(csv_dir=folder, dialect="siemens-xy"))
export = result.summary()["export"]
print(f"{export['dialect']}: {export['points']} points (limit {export['point_limit']})")
print(f"worst error against the schedule: {1e3 * max(export['position_error_m']):.4f} mm")
print(*(folder / "agv1.csv").read_text().splitlines()[:3], sep="\n")  # x = time (s); y = axis (mm)

# The files alone, checked against the scenario: they pass.
verdict = check_profiles(scenario, folder, dialect="siemens-xy")
print(f"as written: passed {verdict.passed}, closest approach {verdict.check.report.min_separation:.4f} m")

# Someone moves one point of agv1 by 1 cm (10 mm): the checker says what breaks, in plain words
# (the quantity, its value and limit, when and where on the track). Where each failure lies in the
# schedule read back from the tables is in ``edited.check.report.details`` (``trajgen check
# --verbose`` prints it).
path = folder / "agv1.csv"
lines = path.read_bytes().decode("ascii").split("\r\n")
x, y = lines[300].split(";")
lines[300] = f"{x};{float(y) + 10.0:.9f}"
path.write_bytes("\r\n".join(lines).encode("ascii"))
edited = check_profiles(scenario, folder, dialect="siemens-xy")
print(f"edited: passed {edited.passed}")
for failure in edited.failures:
    print(f"  {failure}")
print(f"violations after moving one point by 1 cm: {len(edited.failures)}")
if scratch is not None:
    print(f"(the files in {output} are removed now: set TRAJGEN_EXAMPLE_OUTPUT=DIR to keep them)")
    scratch.cleanup()
