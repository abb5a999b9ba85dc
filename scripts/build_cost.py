#!/usr/bin/env python3
"""The build's cost by room, from Ninja's log of a build from scratch: seconds per
translation unit summed by room, the slowest units, and the links. Prints Markdown.

The fuzz targets are a project of their own (cmake/fuzz.cmake) that the main build runs as
one step; where its own log is there (BUILD/fuzz/.ninja_log) its steps are counted instead
of that one step, whose wall time hides the jobs it ran side by side.

Usage: python3 scripts/build_cost.py [BUILD_DIR]   (default build/; run after a clean build,
e.g. in a fresh clone: bash scripts/build.sh && python3 scripts/build_cost.py)
"""
import collections
import os
import sys

FUZZ_ROOM = "fuzz targets (clang, their own project)"
FUZZ_STEP = "saresgs_fuzz-stamp/saresgs_fuzz-build"


def room_of(output):
    """The room a Ninja output of the main build belongs to, from its object path."""
    p = output.replace("\\", "/")
    if FUZZ_STEP in p:
        return FUZZ_ROOM
    if "/CMakeFiles/" not in p:
        return "links and other steps"
    target_dir, obj = p.split("/CMakeFiles/", 1)
    if target_dir.startswith("tests"):
        name = obj.split(".dir/", 1)[0]
        return "tests/" + name.replace("test_", "")
    return target_dir.split("/")[0] or "top"


def read_log(path):
    """{output: (start ms, end ms)}: each step once (a step can write several outputs, one
    line each: counted by its command's hash), the last run of each step."""
    by_command = {}
    with open(path) as f:
        header = f.readline()
        if not header.startswith("# ninja log"):
            sys.exit(f"{path}: not a Ninja log")
        for line in f:
            start, end, _mtime, output, command = line.rstrip("\n").split("\t")
            by_command[command] = (output, int(start), int(end))
    return {output: (s, e) for output, s, e in by_command.values()}


def unit_name(output):
    target, _, unit = output.partition(".dir/")
    unit = unit.removesuffix(".o")
    if unit.startswith("Unity/"):  # a unity batch (cmake/unity.cmake): name its target
        unit = f"{target.rsplit('/', 1)[-1]}: {unit.removesuffix('.cxx')}"
    return unit


def cost(build):
    """(steps, wall seconds, {room: seconds}, [(seconds, unit)]) of the build in BUILD."""
    entries = read_log(os.path.join(build, ".ninja_log"))
    wall = (max(e for _, e in entries.values()) - min(s for s, _ in entries.values())) / 1e3
    fuzz_log = os.path.join(build, "fuzz", ".ninja_log")
    fuzz = read_log(fuzz_log) if os.path.exists(fuzz_log) else {}
    if fuzz:
        entries = {o: t for o, t in entries.items() if FUZZ_STEP not in o}
    by_room = collections.defaultdict(float)
    units = []
    for output, (s, e) in entries.items():
        by_room[room_of(output)] += (e - s) / 1e3
        if output.endswith(".o"):
            units.append(((e - s) / 1e3, unit_name(output)))
    for output, (s, e) in fuzz.items():
        by_room[FUZZ_ROOM] += (e - s) / 1e3
        if output.endswith(".o"):
            units.append(((e - s) / 1e3, "fuzz: " + unit_name(output)))
    return len(entries) + len(fuzz), wall, by_room, units


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    steps, wall, by_room, units = cost(build)
    total = sum(by_room.values())
    print(f"Build steps: {steps}, wall {wall:.0f} s, steps summed {total:.0f} s "
          f"(parallel steps overlap: the sum is about the CPU time)\n")
    print("| room | seconds | share |\n|---|---:|---:|")
    for room, sec in sorted(by_room.items(), key=lambda kv: -kv[1]):
        print(f"| {room} | {sec:.0f} | {100 * sec / total:.0f} % |")
    print("\nSlowest translation units:\n\n| seconds | unit |\n|---:|---|")
    for sec, unit in sorted(units, reverse=True)[:15]:
        print(f"| {sec:.1f} | {unit} |")


if __name__ == "__main__":
    main()
