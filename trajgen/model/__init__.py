"""The data model: schedules and their pieces, paths, profiles, the coordination diagram, summaries.

Everything here is computed from routes and limits; nothing reads or writes files, and nothing here
imports the timing methods, the verifier or the exporters above it.
"""
