"""The package version, apart from the package so that any module can read it."""

__version__ = "0.3.0"
