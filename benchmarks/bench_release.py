"""The release bundle's build time, this tree against an earlier commit, side by side (issue 56),
and its x86_64 binaries' code against that commit's.

    python benchmarks/bench_release.py --against COMMIT [--repeats N]

Each run is ``python build_fmu.py --release`` in a fresh process, in this tree and in a git
worktree of COMMIT, alternately, each with a fresh, empty zig cache (zig builds what it needs
for a target on first use, as on a fresh machine). Prints each run's wall time and CPU time (the
build's process and its compilers), the FMUs and binaries in each bundle, and the median ratio of
the pairs.

Then the objects: the sources of every FMU of both bundles compiled once more by gcc and mingw
with the build's flags (``-c``: no linker, whose image base and build id differ by build), with
the instantiation token (a hash of the source) set equal: the disassembly, data and relocations
compared.
"""
from __future__ import annotations

import argparse
import os
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import zipfile
from pathlib import Path

from fmu_src.fmi.native.build import FLAGS, WARNINGS
import harness

REPO = Path(__file__).resolve().parents[1]
TOKEN = re.compile(rb'(?:guid|instantiationToken)="(\{[^"]+\})"')


def release(tree: Path, out: Path) -> tuple[float, float]:
    """(wall [s], the children's CPU [s]) of ``build_fmu.py --release`` in ``tree``, fresh zig cache."""
    with tempfile.TemporaryDirectory(prefix="zig_cache_") as cache:
        environment = dict(os.environ, ZIG_GLOBAL_CACHE_DIR=cache, ZIG_LOCAL_CACHE_DIR=cache)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        started = time.perf_counter()
        subprocess.run([sys.executable, "build_fmu.py", "--release", "--out", str(out)], cwd=tree, env=environment,
                       check=True, stdout=subprocess.DEVNULL)
        wall = time.perf_counter() - started
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def binaries(bundle: Path) -> int:
    return sum(name.startswith("binaries/") and not name.endswith("/")
               for fmu in bundle.glob("*.fmu") for name in zipfile.ZipFile(fmu).namelist())


def object_dump(fmu: Path, compiler: str, folder: Path) -> str:
    """The disassembly, sections and relocations of the FMU's sources compiled by ``compiler``
    with the build's flags, its instantiation token replaced by a fixed one."""
    with zipfile.ZipFile(fmu) as archive:
        description = archive.read("modelDescription.xml")
        token = TOKEN.search(description)[1]
        identifier = re.search(rb'modelIdentifier="(\w+)"', description)[1].decode()
        for name in archive.namelist():
            if name.startswith("sources/") and not name.endswith("/"):
                path = folder / name
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_bytes(archive.read(name).replace(token, b"{" + b"0" * (len(token) - 2) + b"}"))
    subprocess.run([compiler, *WARNINGS, *FLAGS, "-c", "-I", str(folder / "sources"), "-o", str(folder / "unit.o"),
                    str(folder / "sources" / f"{identifier}.c")], check=True)
    dump = compiler.replace("gcc", "objdump") if "mingw" in compiler else "objdump"
    text = subprocess.run([dump, "-d", "-r", "-s", str(folder / "unit.o")], capture_output=True, text=True,
                          check=True).stdout
    shutil.rmtree(folder / "sources")
    return text.split("\n", 2)[2]          # without the line naming the file


def compare_objects(new: Path, old: Path, work: Path) -> None:
    compilers = [c for c in ("gcc", "x86_64-w64-mingw32-gcc") if shutil.which(c)]
    equal = total = 0
    for fmu in sorted(new.glob("*.fmu")):
        for compiler in compilers:
            total += 1
            if object_dump(fmu, compiler, work / "new") == object_dump(old / fmu.name, compiler, work / "old"):
                equal += 1
            else:
                print(f"  differs: {fmu.name} ({compiler})")
    print(f"objects of every FMU's sources ({', '.join(compilers)}; code, data, relocations), token aside: "
          f"{equal} of {total} equal to {old.name}'s")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--against", required=True, help="the earlier commit to build side by side")
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    print(harness.provenance())
    with tempfile.TemporaryDirectory(prefix="bench_release_") as work:
        work = Path(work)
        earlier = work / "earlier"
        subprocess.run(["git", "worktree", "add", "--detach", "-q", str(earlier), args.against], cwd=REPO, check=True)
        try:
            trees = {"this tree": REPO, args.against: earlier}
            runs = {name: [] for name in trees}
            for repeat in range(args.repeats):
                for name, tree in trees.items():
                    out = work / f"{name.replace(' ', '_')}-{repeat}"
                    wall, cpu = release(tree, out)
                    runs[name].append((wall, cpu))
                    print(f"  {name:>12}: {wall:6.1f} s wall, {cpu:6.1f} s CPU (the build and its compilers), "
                          f"{len(list(out.glob('*.fmu')))} FMUs, {binaries(out)} binaries", flush=True)
            ratios = [new[0] / old[0] for new, old in zip(runs["this tree"], runs[args.against])]
            print(f"release time, this tree / {args.against}: median {statistics.median(ratios):.2f} "
                  f"(each pair: {', '.join(f'{r:.2f}' for r in ratios)})")
            compare_objects(work / "this_tree-0", work / f"{args.against}-0", work)
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(earlier)], cwd=REPO, check=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
