"""Outputs for controllers: CSV profiles, VDA 5050 orders, and the atomic commit of all files of a run."""

from trajgen.export.atomic import check_output_paths, commit_files
from trajgen.export.csv import (
    DEFAULT_MAX_ROWS,
    HEADER_NAMES,
    CsvOptions,
    Units,
    check_row_limit,
    format_block,
    format_rows,
    profile_chunk_pair,
    profile_chunks,
    profile_paths,
    render_profile,
    write_profiles,
)
from trajgen.export.vda5050 import Vda5050Options, plan_orders, render_manifest, render_orders, write_orders

__all__ = [
    "DEFAULT_MAX_ROWS",
    "HEADER_NAMES",
    "CsvOptions",
    "Units",
    "Vda5050Options",
    "check_output_paths",
    "check_row_limit",
    "commit_files",
    "format_block",
    "format_rows",
    "plan_orders",
    "profile_chunk_pair",
    "profile_chunks",
    "profile_paths",
    "render_manifest",
    "render_orders",
    "render_profile",
    "write_orders",
    "write_profiles",
]
