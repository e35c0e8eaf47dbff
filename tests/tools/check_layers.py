#!/usr/bin/env python3
"""The layering check: every include points down.

Reads <build>/masa_layers.txt (written by cmake/masa_library.cmake: one line per library, its
folder and the libraries it depends on) and scans the C++ files of the source tree. A file belongs
to the library of the deepest library folder that holds it; it may include headers of its own
library and of the libraries below it (its dependencies, directly or through them). Files outside
every library folder (tools/, tests/, bench/, the *_main.cpp entry points) are the top and may
include anything. Exit status 1 and one line per upward include; 0 when the house is in order.

  python3 tests/tools/check_layers.py <build>/masa_layers.txt <source root>
"""
import os
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
TOP_FOLDERS = ("tools", "tests", "bench")


def read_layers(path):
    folders, deps, generated = {}, {}, {}
    with open(path) as f:
        for line in f:
            words = line.split()
            if not words:
                continue
            target, folder, rest = words[0], words[1], words[2:]
            prefixes = [w[len("GENERATED:"):] for w in rest if w.startswith("GENERATED:")]
            for p in prefixes:
                generated[p] = target
            if prefixes:
                folders.setdefault(target, folder)
                continue
            if target in deps:
                sys.exit(f"{path}: library {target} declared twice")
            folders[target] = folder
            deps[target] = rest
    return folders, deps, generated


def closure(deps):
    below = {}

    def visit(t, path):
        if t in below:
            return below[t]
        if t in path:
            sys.exit("dependency cycle: " + " -> ".join(path + [t]))
        reach = set()
        for d in deps.get(t, []):
            reach.add(d)
            reach |= visit(d, path + [t])
        below[t] = reach
        return reach

    for t in deps:
        visit(t, [])
    return below


def owner(path, folder_of):
    """The library whose folder is the deepest prefix of path, or None (the top)."""
    best, best_len = None, -1
    for target, folder in folder_of.items():
        if (path == folder or path.startswith(folder + "/")) and len(folder) > best_len:
            best, best_len = target, len(folder)
    return best


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    layers, root = sys.argv[1], sys.argv[2]
    folder_of, deps, generated = read_layers(layers)
    below = closure(deps)
    problems, files = [], 0
    for top in sorted(set(f.split("/")[0] for f in folder_of.values())):
        for dirpath, _, names in os.walk(os.path.join(root, top)):
            for name in sorted(names):
                if not name.endswith((".cpp", ".hpp")) or name.endswith("_main.cpp"):
                    continue
                rel = os.path.relpath(os.path.join(dirpath, name), root)
                if rel.split("/")[0] in TOP_FOLDERS:
                    continue
                lib = owner(os.path.dirname(rel), folder_of)
                if lib is None:
                    continue
                files += 1
                with open(os.path.join(root, rel), errors="replace") as f:
                    text = f.read()
                for inc in INCLUDE.findall(text):
                    target = next((t for p, t in generated.items() if inc.startswith(p)), None)
                    if target is None:
                        if not os.path.exists(os.path.join(root, inc)):
                            continue  # a header next to the file, or a system header in quotes
                        target = owner(os.path.dirname(inc), folder_of)
                    if target is None or target == lib or target in below.get(lib, set()):
                        continue
                    problems.append(f"{rel}: includes {inc} ({target}), which {lib} does not depend on")
    for p in problems:
        print(p)
    print(f"{files} files of {len(deps)} libraries: {len(problems)} upward include(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
