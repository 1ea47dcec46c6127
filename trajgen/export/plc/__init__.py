"""PLC tables and profile files: written in a controller's dialect, read back and checked.

- :mod:`~trajgen.export.plc.dialects`: the dialects of the profile files (:data:`DIALECTS`);
- :mod:`~trajgen.export.plc.resample`: tables of at most a controller's number of points;
- :mod:`~trajgen.export.plc.tables`: tables as a controller interpolates them, and their limits;
- :mod:`~trajgen.export.plc.table_check`: tables read along the route and verified;
- :mod:`~trajgen.export.plc.files`: both vehicles' tables of a dialect, verified and committed
  (:func:`plc_tables`, :func:`write_tables`);
- :mod:`~trajgen.export.plc.check`: ``trajgen check``, files received or edited, checked against
  the scenario (:func:`check_profiles`).
"""

from typing import TYPE_CHECKING

from trajgen.lazy import lazy_attributes

if TYPE_CHECKING:
    from trajgen.export.plc.check import check_profiles
    from trajgen.export.plc.dialects import DIALECTS, Dialect, DialectName, TableDialect
    from trajgen.export.plc.files import (
        PlcTables,
        check_dialect_method,
        plc_tables,
        table_paths,
        write_tables,
    )

_MODULES = {
    "check": ("check_profiles",),
    "dialects": ("DIALECTS", "Dialect", "DialectName", "TableDialect"),
    "files": ("PlcTables", "check_dialect_method", "plc_tables", "table_paths", "write_tables"),
}
#: Where each name lives: importing the face imports none of them.
_SOURCES = {name: f"{__name__}.{module}" for module, names in _MODULES.items() for name in names}

__all__ = [
    "DIALECTS",
    "Dialect",
    "DialectName",
    "PlcTables",
    "TableDialect",
    "check_dialect_method",
    "check_profiles",
    "plc_tables",
    "table_paths",
    "write_tables",
]

__getattr__, __dir__ = lazy_attributes(__name__, globals(), _SOURCES)
