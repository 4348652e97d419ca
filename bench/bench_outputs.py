"""The benchmark scripts' check of a results file, before any work: cellrt_bench's rules and words
(a folder that is not there, a folder in the file's place, a file there already without
--overwrite). Imported by python_bench.py, python_kinds.py, ab_compare.py and ab_callgrind.py."""
import os


def check_output(parser, option, path, overwrite):
    """Refuses `path` through parser.error (status 2, one line) where a run could not write it or
    would replace a file without --overwrite."""
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        parser.error(f"{option} {path}: no folder {folder} to write it in")
    if os.path.isdir(path):
        parser.error(f"{option} {path}: is a folder")
    if os.path.exists(path) and not overwrite:
        parser.error(f"{option} {path}: file exists (pass --overwrite to replace it)")
