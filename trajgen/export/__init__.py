"""Outputs for controllers: the writers, the reader and their option types.

CSV profiles (:func:`write_profiles`, one row per sample period), PLC tables of a dialect
(:func:`write_tables`), VDA 5050 orders (:func:`write_orders`), each rendered to bytes by its
``render_*`` / :func:`plc_tables` first, and :func:`commit_files`, which writes all files of a run
together or none. :func:`check_profiles` reads exported files back and checks them as a controller
would drive them. Every other name has one import path: its module (``trajgen.export.csv``,
``trajgen.export.plc``, ``trajgen.export.vda5050``, ``trajgen.export.atomic``, ...).
"""

from typing import TYPE_CHECKING

from trajgen.lazy import lazy_attributes

if TYPE_CHECKING:
    from trajgen.export.atomic import commit_files
    from trajgen.export.csv import DEFAULT_MAX_ROWS, CsvOptions, Units, render_profile, write_profiles
    from trajgen.export.plc.check import check_profiles
    from trajgen.export.plc.dialects import DIALECTS, Dialect, DialectName, TableDialect
    from trajgen.export.plc.files import PlcTables, plc_tables, write_tables
    from trajgen.export.vda5050.files import write_orders
    from trajgen.export.vda5050.messages import render_manifest, render_orders
    from trajgen.export.vda5050.options import Vda5050Options

#: Where each name lives: importing one exporter does not import the others.
_SOURCES = {
    "DEFAULT_MAX_ROWS": "trajgen.export.csv",
    "DIALECTS": "trajgen.export.plc.dialects",
    "CsvOptions": "trajgen.export.csv",
    "Dialect": "trajgen.export.plc.dialects",
    "DialectName": "trajgen.export.plc.dialects",
    "PlcTables": "trajgen.export.plc.files",
    "TableDialect": "trajgen.export.plc.dialects",
    "Units": "trajgen.export.csv",
    "Vda5050Options": "trajgen.export.vda5050.options",
    "check_profiles": "trajgen.export.plc.check",
    "commit_files": "trajgen.export.atomic",
    "plc_tables": "trajgen.export.plc.files",
    "render_manifest": "trajgen.export.vda5050.messages",
    "render_orders": "trajgen.export.vda5050.messages",
    "render_profile": "trajgen.export.csv",
    "write_orders": "trajgen.export.vda5050.files",
    "write_profiles": "trajgen.export.csv",
    "write_tables": "trajgen.export.plc.files",
}

__all__ = [
    "DEFAULT_MAX_ROWS",
    "DIALECTS",
    "CsvOptions",
    "Dialect",
    "DialectName",
    "PlcTables",
    "TableDialect",
    "Units",
    "Vda5050Options",
    "check_profiles",
    "commit_files",
    "plc_tables",
    "render_manifest",
    "render_orders",
    "render_profile",
    "write_orders",
    "write_profiles",
    "write_tables",
]

__getattr__, __dir__ = lazy_attributes(__name__, globals(), _SOURCES)
