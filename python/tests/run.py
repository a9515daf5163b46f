"""Runs lucent's pytest suite (the CTest entries python.pytest.<file>) with the interpreter CMake chose.

Exits 77, which CTest reports as a skip, when that interpreter cannot import numpy or pytest.
"""
import importlib.util
import sys

if __name__ == "__main__":  # not when a spawned multiprocessing worker imports this main module
    missing = [m for m in ("numpy", "pytest") if importlib.util.find_spec(m) is None]
    if missing:
        print(f"python tests skipped: {sys.executable} cannot import {' and '.join(missing)} "
              "(Debian: apt-get install python3-numpy python3-pytest, or configure with "
              "-DPython3_EXECUTABLE=<a python3 that has them>)")
        sys.exit(77)

    import pytest

    sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", *sys.argv[1:]]))
