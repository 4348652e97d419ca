"""Runs one pytest file of the Python module's suite for CTest: exit code 77 (shown as skipped) where
pytest or numpy is missing; otherwise pytest's own code. The module comes from PYTHONPATH (the build's
python/ folder)."""
import sys

try:
    import numpy  # noqa: F401
    import pytest
except ImportError as e:
    print(f"skipped: {e} (install python3-pytest and python3-numpy)")
    sys.exit(77)

sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", *sys.argv[1:]]))
