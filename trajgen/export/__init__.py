"""Outputs for controllers: CSV profiles, and the atomic commit of all files of a run."""

from trajgen.export.atomic import check_output_paths, commit_files
from trajgen.export.csv import HEADER_NAMES, CsvOptions, Units, profile_paths, render_profile, write_profiles

__all__ = [
    "HEADER_NAMES",
    "CsvOptions",
    "Units",
    "check_output_paths",
    "commit_files",
    "profile_paths",
    "render_profile",
    "write_profiles",
]
