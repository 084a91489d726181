"""One module per CLI verb (see fvd_bridge.cli).

cli.py imports every verb's module to build the parser (``fvd-bridge --help``),
so a verb's heavy imports are made inside its ``run()`` or the helper that
needs them, not at the top: its engine when nothing else at start-up loads it
(diagnose, export, frames), matplotlib (fvd_bridge.plots), openseespy, fmpy
and dask's distributed.  Everything else is imported at the top."""
