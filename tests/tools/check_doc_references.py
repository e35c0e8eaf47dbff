#!/usr/bin/env python3
"""Every file, program and option that README.md and docs/*.md name exists (issue #54, item 5).

  check_doc_references.py SOURCE_DIR BUILD_DIR

- Links: a Markdown link to a local file resolves (relative to the page).
- Paths: a backticked path under one of the repository's top folders exists (placeholders such as
  <task>, globs and ~ are skipped: they name a family, not a file).
- Programs: build/tools/masa_X, build/bench/bench_X and masa_X name programs the build makes.
- Options: in fenced shell blocks, each --option given to a masa program is one its --help (or
  its subcommand's --help) lists, and each given to a repository script appears in the script.
Prints one line per problem and "FAIL: ..." (exit 1), or "PASS: ..." (exit 0).
"""
import os
import re
import subprocess
import sys

TOP_FOLDERS = ("tasks", "configs", "docs", "experiments", "scripts", "deploy", "tools", "learner", "actors",
               "common", "bench", "tests", "lcmtypes", "cmake", "python")
PLACEHOLDER = re.compile(r"[<>*{}$~]|\.\.\.")


def pages(src):
    out = [os.path.join(src, "README.md")]
    docs = os.path.join(src, "docs")
    out += sorted(os.path.join(docs, f) for f in os.listdir(docs) if f.endswith(".md"))
    return out


def fenced_blocks(text):
    """The shell lines of ```bash / ```sh / ``` blocks, with backslash continuations joined."""
    lines, inside, lang = [], False, ""
    for raw in text.split("\n"):
        if raw.strip().startswith("```"):
            if inside:
                inside = False
            else:
                inside, lang = True, raw.strip()[3:].strip()
            continue
        if inside and lang in ("", "bash", "sh", "shell"):
            lines.append(raw)
    joined, cur = [], ""
    for l in lines:
        if l.rstrip().endswith("\\"):
            cur += l.rstrip()[:-1] + " "
        else:
            joined.append(cur + l)
            cur = ""
    return joined


class Programs:
    def __init__(self, src, build):
        self.src, self.build = src, build
        self.tools = {"masa_" + f[:-4] for f in os.listdir(os.path.join(src, "tools")) if f.endswith(".cpp")}
        self.tools |= {"masa_actor", "masa_learner", "masa_deploy", "masa_sim_robot"}
        self.helps = {}

    def exists(self, name):
        if name.startswith("bench_"):  # bench/bench_X.cpp, or bench/X.cpp built as bench_X
            return any(os.path.exists(os.path.join(self.src, "bench", n + ".cpp")) for n in (name, name[len("bench_"):]))
        return name in self.tools

    def help(self, name, sub=None):
        key = (name, sub)
        if key not in self.helps:
            path = os.path.join(self.build, "tools", name)
            if not os.path.exists(path):
                for d in ("actors", "learner", "deploy/runner", "deploy/sim_robot", "deploy"):
                    if os.path.exists(os.path.join(self.build, d, name)):
                        path = os.path.join(self.build, d, name)
                        break
            args = [path] + ([sub] if sub else []) + ["--help"]
            try:
                r = subprocess.run(args, capture_output=True, text=True, timeout=20)
                self.helps[key] = r.stdout + r.stderr if r.returncode == 0 else None
            except (OSError, subprocess.TimeoutExpired):
                self.helps[key] = None
        return self.helps[key]


def check(src, build):
    problems = []
    progs = Programs(src, build)
    for page in pages(src):
        rel = os.path.relpath(page, src)
        text = open(page, encoding="utf-8").read()
        prose = re.sub(r"```.*?```", "", text, flags=re.S)
        for m in re.finditer(r"\]\(([^)\s]+)\)", prose):
            target = m.group(1).split("#")[0]
            if not target or target.startswith(("http://", "https://", "mailto:")):
                continue
            if not os.path.exists(os.path.normpath(os.path.join(os.path.dirname(page), target))):
                problems.append(f"{rel}: link to {m.group(1)}: no such file")
        for m in re.finditer(r"`([^`\s]+)`", prose):
            token = m.group(1).rstrip(".,:;")
            first = token.split("/")[0]
            if "/" in token and first in TOP_FOLDERS and not PLACEHOLDER.search(token):
                path = os.path.join(src, token.split(":")[0])
                # a source named without its extension names its .hpp/.cpp pair
                if not any(os.path.exists(path + ext) for ext in ("", ".cpp", ".hpp", ".sh", ".py")):
                    problems.append(f"{rel}: `{token}`: no such path")
        for m in re.finditer(r"(?<![\w/.-])(?:build/tools/)?(masa_[a-z_0-9]+)\b", text):
            name = m.group(1)
            if name.startswith(("masa_library", "masa_entry_point", "masa_layers", "masa_unit_tests")):
                continue  # cmake functions and the test binary, not programs a user runs
            if not progs.exists(name) and "build/tools/" in m.group(0):
                problems.append(f"{rel}: build/tools/{name}: no such program")
        for m in re.finditer(r"build/bench/(bench_[a-z_0-9]+)", text):
            if not progs.exists(m.group(1)):
                problems.append(f"{rel}: build/bench/{m.group(1)}: no such benchmark")
        for line in fenced_blocks(text):
            for command in re.split(r"\s(?:&&|\|\||\||;)\s", line.split(" # ")[0]):
                words = command.split()
                if not words:
                    continue
                i = 0
                while i < len(words) and (words[i] in ("xvfb-run", "-a", "nice", "sudo", "time", "env") or "=" in words[i]):
                    i += 1
                if i >= len(words):
                    continue
                prog, args = words[i], words[i + 1:]
                base = os.path.basename(prog)
                options = [a.split("=")[0] for a in args if a.startswith("--") and len(a) > 2]
                if base.startswith("masa_") and progs.exists(base):
                    sub = args[0] if args and re.fullmatch(r"[a-z][a-z_-]*", args[0]) else None
                    helps = [h for h in (progs.help(base), progs.help(base, sub) if sub else None) if h]
                    if not helps:
                        continue  # a program the build lacks here (a dependency missing): not this check's business
                    for o in options:
                        if not any(re.search(re.escape(o) + r"\b", h) for h in helps):
                            problems.append(f"{rel}: `{base} ... {o}`: {base} has no such option")
                elif "/" in prog and prog.split("/")[0] in TOP_FOLDERS and prog.endswith((".sh", ".sbatch", ".py")):
                    path = os.path.join(src, prog)
                    if not os.path.exists(path):
                        problems.append(f"{rel}: {prog}: no such script")
                        continue
                    body = open(path, encoding="utf-8", errors="replace").read()
                    for o in options:
                        if o not in body:
                            problems.append(f"{rel}: `{prog} ... {o}`: the script has no such option")
    return problems


def main():
    src, build = sys.argv[1], sys.argv[2]
    problems = check(src, build)
    for p in problems:
        print(p)
    if problems:
        print(f"FAIL: {len(problems)} names in README.md and docs/ that do not exist")
        sys.exit(1)
    print(f"PASS: every file, program and option named in README.md and docs/ ({len(pages(src))} pages) exists")


if __name__ == "__main__":
    main()
