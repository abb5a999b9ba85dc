#!/usr/bin/env python3
"""The build's cost by room, from Ninja's log of a build from scratch: seconds per
translation unit summed by room, the slowest units, and the links. Prints Markdown.

Usage: python3 scripts/build_cost.py [BUILD_DIR]   (default build/; run after a clean build,
e.g. in a fresh clone: bash scripts/build.sh && python3 scripts/build_cost.py)
"""
import collections
import os
import sys


def room_of(output):
    """The room a Ninja output belongs to, from its object path."""
    p = output.replace("\\", "/")
    if "saresgs_fuzz-stamp/saresgs_fuzz-build" in p:
        return "fuzz targets (clang, their own project)"
    if "/CMakeFiles/" not in p:
        return "links and other steps"
    target_dir, obj = p.split("/CMakeFiles/", 1)
    if target_dir.startswith("tests"):
        name = obj.split(".dir/", 1)[0]
        return "tests/" + name.replace("test_", "")
    return target_dir.split("/")[0] or "top"


def main():
    build = sys.argv[1] if len(sys.argv) > 1 else "build"
    path = os.path.join(build, ".ninja_log")
    by_command = {}
    with open(path) as f:
        header = f.readline()
        if not header.startswith("# ninja log"):
            sys.exit(f"{path}: not a Ninja log")
        for line in f:
            start, end, _mtime, output, command = line.rstrip("\n").split("\t")
            # One step can write several outputs (one line each): count it once, by its
            # command's hash; the last run of each step counts.
            by_command[command] = (output, int(start), int(end))
    entries = {output: (s, e) for output, s, e in by_command.values()}
    wall = (max(e for _, e in entries.values()) - min(s for s, _ in entries.values())) / 1e3
    by_room = collections.defaultdict(float)
    units = []
    for output, (s, e) in entries.items():
        sec = (e - s) / 1e3
        by_room[room_of(output)] += sec
        if output.endswith(".o"):
            units.append((sec, output))
    total = sum(by_room.values())
    print(f"Build steps: {len(entries)}, wall {wall:.0f} s, steps summed {total:.0f} s "
          f"(parallel steps overlap: the sum is about the CPU time)\n")
    print("| room | seconds | share |\n|---|---:|---:|")
    for room, sec in sorted(by_room.items(), key=lambda kv: -kv[1]):
        print(f"| {room} | {sec:.0f} | {100 * sec / total:.0f} % |")
    print("\nSlowest translation units:\n\n| seconds | unit |\n|---:|---|")
    for sec, output in sorted(units, reverse=True)[:15]:
        target, _, unit = output.partition(".dir/")
        unit = unit.removesuffix(".o")
        if unit.startswith("Unity/"):  # a unity batch (cmake/unity.cmake): name its target
            unit = f"{target.rsplit('/', 1)[-1]}: {unit.removesuffix('.cxx')}"
        print(f"| {sec:.1f} | {unit} |")


if __name__ == "__main__":
    main()
