#!/usr/bin/env bash
# Every file, program and option named in README.md and docs/ exists (issue #54, item 5;
# tests/tools/check_doc_references.py), and the check finds each kind of drift: a copy of the
# pages with a dead link, a path that is gone and an option a program does not have must fail,
# naming all three.
#   tests/integration/doc_references.sh SOURCE_DIR BUILD_DIR WORK_DIR
set -uo pipefail
src=$(cd "$1" && pwd) build=$(cd "$2" && pwd) work=$3
fail() { echo "FAIL: $*"; exit 1; }
check="$src/tests/tools/check_doc_references.py"
out=$(/usr/bin/python3 "$check" "$src" "$build") || fail "the pages name what does not exist: $out"
rm -rf "$work" && mkdir -p "$work/drift" && cd "$work/drift" || fail "no work directory"
for entry in "$src"/*; do [ "$(basename "$entry")" = docs ] || [ "$(basename "$entry")" = README.md ] || ln -s "$entry" .; done
cp -r "$src/docs" "$src/README.md" .
cat >> README.md << 'MD'
See [the cluster page](docs/no_such_page.md) and `configs/recipes/no_such_recipe.yaml`.

```bash
build/tools/masa_eval tasks/a1_beam/policy/policy.bin --episodez 20
```
MD
drift=$(/usr/bin/python3 "$check" "$work/drift" "$build") && fail "a drifted README passed: $drift"
for what in "docs/no_such_page.md: no such file" "no_such_recipe.yaml\`: no such path" "--episodez\`: masa_eval has no such option"; do
  grep -qF -- "$what" <<< "$drift" || fail "the drift '$what' went unreported: $drift"
done
echo "$out"
echo "PASS: the pages name only what exists, and a dead link, a gone path and an unknown option are each found"
