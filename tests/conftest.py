"""Shared fixtures: the ../shared data folder, synthetic sinusoidal records, CSV writing."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED = (REPO / ".." / "shared").resolve()
DEVICE_FILES = ("labcontrol_mrdamper_4.1_0V.mat", "labcontrol_mrdamper_4.2_0.88V.mat")


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    """The read-only ../shared folder next to the repository; skips when absent."""
    if not SHARED.is_dir():
        pytest.skip(f"{SHARED} is absent")
    return SHARED


@pytest.fixture(scope="session")
def device_files(shared_dir) -> list[Path]:
    """The two real MR-damper tests in ../shared/devices (x_F: mm, mm/s, N)."""
    paths = [shared_dir / "devices" / f for f in DEVICE_FILES]
    missing = [p.name for p in paths if not p.is_file()]
    if missing:
        pytest.skip(f"../shared/devices lacks {', '.join(missing)}")
    return paths


def sine(n_cycles: float = 3.0, freq: float = 1.0, dt: float = 0.01, amp: float = 20.0,
         c: float = 2.0) -> dict:
    """A viscous sinusoidal test: d = amp sin(2 pi f t) [mm], v [mm/s], F = c v [kN]."""
    t = np.arange(int(round(n_cycles / freq / dt)) + 1) * dt
    w = 2 * np.pi * freq
    d = amp * np.sin(w * t)
    v = amp * w * np.cos(w * t)
    return {"t": t, "d": d, "F": c * v, "v": v}


def csv_text(header: str, columns: list, comments: tuple = ()) -> str:
    """CSV text: '# ' comment lines, the header, then rows of %.10g values."""
    lines = [f"# {c}" for c in comments] + [header]
    lines += [",".join(f"{x:.10g}" for x in row) for row in zip(*columns)]
    return "\n".join(lines) + "\n"


@pytest.fixture
def write_csv(tmp_path):
    """Factory: write_csv(name, header, columns, comments=()) -> Path in tmp_path."""
    def write(name: str, header: str, columns: list, comments: tuple = ()) -> Path:
        path = tmp_path / name
        path.write_text(csv_text(header, columns, comments))
        return path
    return write


def cli_env() -> dict:
    """Environment for running the CLI in a subprocess."""
    env = dict(os.environ)
    env.setdefault("MPLBACKEND", "Agg")
    return env


CLI = [sys.executable, "-m", "fvd_bridge.cli"]


#: a user effect file (hardening spring) used by the plugin tests
PLUGIN = '''
import numpy as np
from fvd_bridge.effects import Effect, Parameter

def cubic(P, t, x, xv, xa):
    """Hardening spring K3 x^3 [kN], K3 in kN/mm^3."""
    return P[:, 0:1] * np.asarray(x) ** 3

EFFECTS = [Effect(name="cubic_spring", stage="parallel", none=(0.0,), function=cubic,
                  parameters=(Parameter("K3", "kN/mm^3", (0.0, 1.0),
                                        lambda s: (0.0, 0.5 * s["F"] / s["d"] ** 3), "cubic stiffness"),),
                  equation="+ K3 x^3", summary="a hardening spring", symptom="force grows with d^3",
                  cause="a hardening spring")]
'''
