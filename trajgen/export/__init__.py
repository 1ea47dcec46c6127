"""Outputs for controllers: CSV profiles, and the atomic commit of all files of a run."""

from trajgen.export.atomic import check_output_paths, commit_files
from trajgen.export.csv import (
    DEFAULT_MAX_ROWS,
    HEADER_NAMES,
    CsvOptions,
    Units,
    check_row_limit,
    format_rows,
    profile_chunks,
    profile_paths,
    render_profile,
    write_profiles,
)

__all__ = [
    "DEFAULT_MAX_ROWS",
    "HEADER_NAMES",
    "CsvOptions",
    "Units",
    "check_output_paths",
    "check_row_limit",
    "commit_files",
    "format_rows",
    "profile_chunks",
    "profile_paths",
    "render_profile",
    "write_profiles",
]
