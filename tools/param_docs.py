#!/usr/bin/env python3
"""Rewrites the parameter tables of docs/KDTREE.md, docs/BIH.md, docs/BVH.md and docs/EMBREE.md from the tables
that validate the parameters, as `cellrt info --params KIND` prints them (the test
Params.DocumentsPrintTheTablesThatValidate fails until they agree). That test also compares the
`<!-- params:cuda -->` table of docs/GPU.md with the CUDA backend's memory parameters
(detail::device_memory_params(), src/cuda/device_memory.cpp), which `cellrt info --params` cannot
print: this script leaves that table alone; it is kept by hand.

    tools/param_docs.py [BUILD]      # BUILD: the build folder, build/ by default
"""
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
DOCS = {"kd": "KDTREE.md", "bih": "BIH.md", "bvh": "BVH.md", "auto": "BVH.md", "embree": "EMBREE.md"}


def table(cellrt, kind):
    out = subprocess.run([cellrt, "info", "--params", kind], check=True, capture_output=True, text=True).stdout
    return "".join(line + "\n" for line in out.splitlines() if line.startswith("|"))


def main():
    build = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "build"
    cellrt = str(build / "cellrt")
    for kind, name in DOCS.items():
        doc = ROOT / "docs" / name
        text = doc.read_text()
        marked = re.compile(r"(<!-- params:%s -->\n).*?(<!-- /params -->)" % re.escape(kind), re.S)
        if not marked.search(text):
            sys.exit(f"{doc}: no <!-- params:{kind} --> ... <!-- /params --> block")
        try:
            rows = table(cellrt, kind)
        except subprocess.CalledProcessError:
            print(f"skipping {kind}: {cellrt} does not offer it")
            continue
        doc.write_text(marked.sub(lambda m: m.group(1) + rows + m.group(2), text))
        print(f"wrote the {kind} table of {doc}")


if __name__ == "__main__":
    main()
