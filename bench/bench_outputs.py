"""The benchmark scripts' check of a results file, before any work: cellrt_bench's rules and words
(a folder that is not there, a folder in the file's place, a file there already without
--overwrite), the reading of its input files (load_json) and the one-line errors of every script (run)."""
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


class InputError(Exception):
    """A bad input file, in words that name it: printed by run() as it is."""


def load_json(path, rows=False):
    """The JSON in `path`; with rows=True, a non-empty list (a benchmark's rows). Raises InputError
    naming the file where it is not JSON or holds no rows (json's own message names no file; an
    empty list printed a table's header or nothing, with status 0: found by audit, 2026-12-08)."""
    import json
    with open(path, encoding="utf-8") as f:
        try:
            data = json.load(f)
        except (json.JSONDecodeError, UnicodeDecodeError) as e:
            raise InputError(f"{path}: not JSON: {e}") from None
    if rows and (not isinstance(data, list) or not data):
        raise InputError(f"{path}: holds no rows (a benchmark's JSON is a non-empty list)")
    return data


def run(main, name):
    """Runs a script's main() and turns what a bad input raises (a file that is not there or not
    readable, JSON that is not JSON, a file of another program or shape, a value that does not parse)
    into one line, `NAME: error: ...`, and status 1, instead of a traceback (found by audit,
    2026-12-07). main's own return value is the status."""
    import json
    import statistics
    import sys
    try:
        return main()
    except InputError as e:
        sys.exit(f"{name}: error: {e}")
    except KeyError as e:
        sys.exit(f"{name}: error: an input has no field {e} (is it the file this script reads?)")
    except json.JSONDecodeError as e:
        sys.exit(f"{name}: error: not JSON: {e}")
    except (OSError, ValueError, TypeError, AttributeError, IndexError, ZeroDivisionError,
            statistics.StatisticsError) as e:
        sys.exit(f"{name}: error: {type(e).__name__}: {e}")
