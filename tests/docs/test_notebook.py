"""examples/notebook.ipynb runs as written (nbclient, a fresh kernel, in a
scratch folder): arrays to a calibration, its report, diagnose's better
model, OpenSees and an FMU, each cell's own asserts checking the numbers."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

NOTEBOOK = Path(__file__).resolve().parents[2] / "examples" / "notebook.ipynb"


def test_the_notebook_runs_as_written(tmp_path, monkeypatch):
    monkeypatch.setenv("MPLBACKEND", "Agg")
    shutil.copy(NOTEBOOK, tmp_path / NOTEBOOK.name)
    nb = nbformat.read(str(tmp_path / NOTEBOOK.name), as_version=4)
    nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs if o.output_type == "error"]
    assert not errors
    html = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs if "text/html" in o.get("data", {})]
    assert len(html) >= 2  # the calibration's and the diagnosis' tables
    assert (tmp_path / "damper.fmu").exists() and (tmp_path / "damper.yaml").exists()
