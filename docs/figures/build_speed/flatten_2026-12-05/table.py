#!/usr/bin/env python3
"""The kd-tree's and the SAH BIH's builds on 1 and 2 threads, 08d9392 (old: the layout on one thread)
against the layout on the build's threads (new), five rounds in turn (run.sh; docs/BUILD_SPEED.md,
"The layout on the build's threads"): bih_span_2026-12-05/table.py's table of these runs."""
import os
import runpy
import sys

here = os.path.dirname(os.path.abspath(__file__))
sys.argv = [sys.argv[0], sys.argv[1] if len(sys.argv) > 1 else here, 'kd', 'bih@split=sah', 'embree']
runpy.run_path(os.path.join(here, '..', 'bih_span_2026-12-05', 'table.py'), run_name='__main__')
