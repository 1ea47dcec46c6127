"""Outputs for controllers: CSV profiles, VDA 5050 orders, and the atomic commit of all files of a run."""

from typing import TYPE_CHECKING

from trajgen.lazy import lazy_attributes

if TYPE_CHECKING:
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
    from trajgen.export.dialects import DIALECTS, Dialect, DialectName, TableDialect
    from trajgen.export.plc import PlcTables, plc_tables, table_paths, write_tables
    from trajgen.export.vda5050 import (
        Vda5050Options,
        plan_orders,
        render_manifest,
        render_orders,
        write_orders,
    )

#: Where each name lives: importing one exporter does not import the others.
_SOURCES = {
    "DIALECTS": "trajgen.export.dialects",
    "Dialect": "trajgen.export.dialects",
    "DialectName": "trajgen.export.dialects",
    "PlcTables": "trajgen.export.plc",
    "TableDialect": "trajgen.export.dialects",
    "plc_tables": "trajgen.export.plc",
    "table_paths": "trajgen.export.plc",
    "write_tables": "trajgen.export.plc",
    "CsvOptions": "trajgen.export.csv",
    "DEFAULT_MAX_ROWS": "trajgen.export.csv",
    "HEADER_NAMES": "trajgen.export.csv",
    "Units": "trajgen.export.csv",
    "Vda5050Options": "trajgen.export.vda5050",
    "check_output_paths": "trajgen.export.atomic",
    "check_row_limit": "trajgen.export.csv",
    "commit_files": "trajgen.export.atomic",
    "format_block": "trajgen.export.csv",
    "format_rows": "trajgen.export.csv",
    "plan_orders": "trajgen.export.vda5050",
    "profile_chunk_pair": "trajgen.export.csv",
    "profile_chunks": "trajgen.export.csv",
    "profile_paths": "trajgen.export.csv",
    "render_manifest": "trajgen.export.vda5050",
    "render_orders": "trajgen.export.vda5050",
    "render_profile": "trajgen.export.csv",
    "write_orders": "trajgen.export.vda5050",
    "write_profiles": "trajgen.export.csv",
}

__all__ = [
    "DEFAULT_MAX_ROWS",
    "DIALECTS",
    "HEADER_NAMES",
    "CsvOptions",
    "Dialect",
    "DialectName",
    "PlcTables",
    "TableDialect",
    "Units",
    "Vda5050Options",
    "check_output_paths",
    "check_row_limit",
    "commit_files",
    "format_block",
    "format_rows",
    "plan_orders",
    "plc_tables",
    "profile_chunk_pair",
    "profile_chunks",
    "profile_paths",
    "render_manifest",
    "render_orders",
    "render_profile",
    "table_paths",
    "write_orders",
    "write_profiles",
    "write_tables",
]


__getattr__, __dir__ = lazy_attributes(__name__, globals(), _SOURCES)
