#!/usr/bin/env python3
"""The unit tests compile in batches (CMake's unity build, tests/CMakeLists.txt): several test files
become one translation unit, so two files that both define a helper `smallConfig` at namespace scope
either fail to build or, worse, overload each other and a call silently takes the other file's. This
check fails when any namespace-scope name (function, constant, type, alias) is defined in two test
files, whatever batch they fall in today: adding a file reshuffles the batches.

It reads the house style: namespace-scope declarations start at column 0, everything inside a body
is indented. Exit status 1 and one line per shared name; 0 when every name is one file's.

  python3 tests/tools/check_unity_names.py <folder of the unit test files>
"""
import collections
import glob
import os
import re
import sys

# A type, an alias, or a variable or function declaration whose name precedes '(', '=', '{', '[' or ';'.
TYPE = re.compile(r'^(?:template\s*<.*>\s*)?(?:struct|class|enum(?:\s+class)?|union)\s+([A-Za-z_]\w*)')
ALIAS = re.compile(r'^using\s+([A-Za-z_]\w*)\s*=')
DECL = re.compile(r'^(?:(?:static|inline|constexpr|const|extern|template\s*<[^>]*>)\s+)*'
                  r'[A-Za-z_][\w:<>,\s\*&]*?[\s\*&]([A-Za-z_]\w*)\s*(?:\(|=|\{|\[|;)')
NOT_DECLARATIONS = ('namespace', 'TEST', 'INSTANTIATE_TEST', 'TYPED_TEST', 'REGISTER_TYPED', 'using namespace',
                    'extern "C"', 'return', '#', '//', '/*', '*', '}', '{', 'template <')


def names_of(path):
    names = set()
    for line in open(path, encoding='utf-8'):
        if not line.strip() or line[0] in ' \t' or line.startswith(NOT_DECLARATIONS):
            continue
        for pattern in (TYPE, ALIAS, DECL):
            m = pattern.match(line)
            if m:
                if m.group(1) != 'operator':
                    names.add(m.group(1))
                break
    return names


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    owners = collections.defaultdict(list)
    files = sorted(glob.glob(os.path.join(sys.argv[1], '*.cpp')))
    for path in files:
        for name in names_of(path):
            owners[name].append(os.path.basename(path))
    shared = {name: where for name, where in owners.items() if len(where) > 1}
    for name in sorted(shared):
        print(f"{name}: defined in {', '.join(shared[name])}: give each file its own name "
              "(the unit tests compile in batches)")
    print(f"{len(files)} test files, {len(owners)} namespace-scope names, {len(shared)} shared")
    return 1 if shared else 0


if __name__ == '__main__':
    sys.exit(main())
