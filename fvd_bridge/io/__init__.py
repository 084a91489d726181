"""Writing outputs: staged directories, YAML/CSV/JSON helpers."""
