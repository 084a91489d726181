"""One module per CLI verb (see fvd_bridge.cli)."""
