"""The test suite of trajgen, topology and limits."""
