"""Exporters of calibrated damper models: OpenSees (command tuples -> script or apply)."""

from .opensees import Export, apply, opensees_export, to_script

__all__ = ["Export", "apply", "opensees_export", "to_script"]
