#!/usr/bin/env python3
"""The library's floors, drawn from its own #include lines, and checked.

Each folder of src/ and include/fretbuzz/ sits on a floor; a file may include files of its
own folder and of folders on lower floors, never higher or beside it. Front ends (cli/,
python/bindings/, plugin/) sit above everything. Run with --draw to print the picture of
the folders and the edges between them (Mermaid, as in docs/architecture.md); the exit
status is 1 if any include goes up or sideways, with the file and line of each.
"""
import argparse
import collections
import os
import re
import sys

# Bottom to top. Folders on one floor do not include each other.
FLOORS = [
    ["base"],                 # Error.hpp, Version.hpp
    ["numerics"],             # sine transform, modal basis, kernels, root finders, time profiles
    ["model", "geometry"],    # string models, obstacle shapes
    ["case"],                 # Case.hpp: one run's description
    ["scheme"],               # the modal scheme: plan, stepper, contact, played parts
    ["input", "run"],         # case files and tables read / the run loop and its observers
    ["output", "reference"],  # writers / the independent finite-difference check
    ["analysis"],             # estimation from recordings, buzz metrics
    ["sweep", "realtime"],    # many runs, convergence / the real-time engine
    ["setup"],                # the set-up bench
    ["cli", "python", "plugin"],  # front ends
]
FLOOR_OF = {name: level for level, names in enumerate(FLOORS) for name in names}
TOP_LEVEL = {"Error.hpp": "base", "Version.hpp": "base", "SubnormalFlush.hpp": "base", "Case.hpp": "case", "RunBounds.hpp": "case", "Case.cpp": "case", "Error.cpp": "base"}
INCLUDE = re.compile(r'\s*#\s*include\s+"([^"]+)"')


def folder_of(relative):
    """The folder (floor name) of a path relative to the repository root, or None."""
    parts = relative.split(os.sep)
    if parts[0] == "src" and len(parts) >= 2:
        return parts[1] if len(parts) > 2 else TOP_LEVEL.get(parts[1])
    if parts[0] == "include" and len(parts) >= 3 and parts[1] == "fretbuzz":
        return parts[2] if len(parts) > 3 else TOP_LEVEL.get(parts[2])
    if parts[0] in ("cli", "plugin"):
        return parts[0]
    if parts[0] == "python" and len(parts) > 1 and parts[1] == "bindings":
        return "python"
    return None


def target_folder(including, included):
    if included.startswith("fretbuzz/"):
        rest = included.split("/")
        return rest[1] if len(rest) > 2 else TOP_LEVEL.get(rest[1])
    return folder_of(os.path.normpath(os.path.join(os.path.dirname(including), included)))


def scan(root):
    edges = collections.defaultdict(set)
    violations = []
    for top in ("src", "include", "cli", "plugin", os.path.join("python", "bindings")):
        for directory, _, names in os.walk(os.path.join(root, top)):
            for name in sorted(names):
                if not name.endswith((".cpp", ".hpp", ".h")):
                    continue
                relative = os.path.relpath(os.path.join(directory, name), root)
                source = folder_of(relative)
                if source is None:
                    continue
                with open(os.path.join(root, relative), encoding="utf-8") as text:
                    for number, line in enumerate(text, 1):
                        match = INCLUDE.match(line)
                        if not match:
                            continue
                        target = target_folder(relative, match.group(1))
                        if target is None or target == source:
                            continue
                        edges[source].add(target)
                        if target not in FLOOR_OF:
                            violations.append(f"{relative}:{number}: includes {match.group(1)} from a folder on no floor")
                        elif source not in FLOOR_OF:
                            violations.append(f"{relative}:{number}: its folder '{source}' is on no floor")
                        elif FLOOR_OF[target] >= FLOOR_OF[source]:
                            violations.append(f"{relative}:{number}: {source} includes {match.group(1)} "
                                              f"({target}, a floor {'above' if FLOOR_OF[target] > FLOOR_OF[source] else 'beside'} it)")
    return edges, violations


def draw(edges):
    lines = ["flowchart BT"]
    for level, names in enumerate(FLOORS):
        lines.append(f"  subgraph floor{level}[\" \"]")
        lines.append("    direction LR")
        lines.extend(f"    {n}" for n in names)
        lines.append("  end")
    for source in sorted(edges):
        for target in sorted(edges[source]):
            lines.append(f"  {source} --> {target}")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("root", nargs="?", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
    parser.add_argument("--draw", action="store_true", help="print the folders and their edges (Mermaid)")
    args = parser.parse_args()
    edges, violations = scan(os.path.abspath(args.root))
    if args.draw:
        print(draw(edges))
    for v in violations:
        print(v, file=sys.stderr)
    if violations:
        print(f"{len(violations)} include(s) go up or sideways between floors", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
