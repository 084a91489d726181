"""What compiling an FMU needs on this machine: cmake, the build tool of its
generator and a C compiler (FMPy's CMake project builds the binary; its FMI
headers come with FMPy), checked before anything is written, each missing
one named with the Debian package that brings it."""

from __future__ import annotations

import os
import re
import shutil

#: C compilers CMake looks for when CC is unset (its default search, the common part)
C_COMPILERS = ("cc", "gcc", "clang")
#: headers of the C library the FMU's sources include: missing ones mean the C library's dev package
LIBC_HEADERS = ("math.h", "stdlib.h", "stdio.h", "string.h", "stdbool.h", "stdint.h", "stddef.h", "float.h")


def missing_tools(environ=None) -> list[tuple[str, tuple[str, ...]]]:
    """The tools building an FMU needs and this machine lacks, as (what, Debian
    packages): cmake; make, the build tool of CMake's default generator on Unix
    (unless CMAKE_GENERATOR names another); a C compiler (CC, else cc, gcc or
    clang on PATH).  On Windows CMake finds Visual Studio itself: only cmake."""
    env = os.environ if environ is None else environ
    path = env.get("PATH", os.defpath)
    missing = []
    if shutil.which("cmake", path=path) is None:
        missing.append(("cmake", ("cmake",)))
    if os.name == "nt":
        return missing
    if not env.get("CMAKE_GENERATOR") and shutil.which("make", path=path) is None:
        missing.append(("make", ("make",)))
    cc = env.get("CC", "").split()
    found = shutil.which(cc[0], path=path) if cc else any(shutil.which(c, path=path) for c in C_COMPILERS)
    if not found:
        what = f"the C compiler CC={env['CC']}" if cc else "a C compiler (cc, gcc or clang)"
        missing.append((what, ("gcc", "libc6-dev")))
    return missing


def toolchain_problem(environ=None) -> str | None:
    """One line naming what to install when building an FMU cannot work here
    (``missing_tools``), else None."""
    missing = missing_tools(environ)
    if not missing:
        return None
    what = [m for m, _ in missing]
    packages = [p for _, pkgs in missing for p in pkgs]
    listed = what[0] if len(what) == 1 else ", ".join(what[:-1]) + " and " + what[-1]
    return (f"building an FMU needs {listed}, not found on PATH: install "
            f"{'it' if len(what) == 1 else 'them'} (Debian: sudo apt-get install {' '.join(packages)})")


def build_log_problem(log: str) -> str | None:
    """One line for a compile that failed because the C library's headers are
    missing (the compiler without libc6-dev), else None (a failure of the
    sources themselves: shown with its log)."""
    found = re.search(r"fatal error: ([\w./]+\.h): No such file", log)
    if found and found.group(1) in LIBC_HEADERS:
        return (f"compiling the FMU: the C library's header {found.group(1)} is missing: install it "
                f"(Debian: sudo apt-get install libc6-dev)")
    return None
