#!/usr/bin/env python3
"""The README's examples, run as a new user runs them (ctest readme_examples).

Every ```sh block of README.md (then of the other Markdown files named, in their order) is run by
one bash (so that a variable one block sets, such as $scratch, is there for the next), from the
root of a fresh copy of the source tree whose build-release/ is this build. A block fails the test when a command in it fails
(bash -e -o pipefail), unless an HTML comment on the line above the fence says otherwise:

  <!-- readme-test: skip (why) -->    not run (set-up, a second build, long campaigns)
  <!-- readme-test: exit N -->        the block must end with exit status N (e.g. 3: limits failed)
  <!-- readme-test: needs WHAT -->    run only when WHAT is a program on PATH or a path in the copy
  <!-- readme-test: output -->        above a plain ``` block: the stdout of the last block run,
                                      line by line; a line "..." stands for any lines, and the
                                      scratch folder prints as $scratch

The copy must not change: examples write into their scratch folder, never into the clone.

  python3 tests/readme_test.py --source-dir . --build-dir build-release [docs/factory.md ...]
"""

import argparse
import difflib
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

MARKER = re.compile(r"^\s*<!--\s*readme-test:\s*(.*?)\s*-->\s*$")
FENCE = re.compile(r"^(\s*)```\s*([\w+-]*)\s*$")
# What the copy leaves out: build trees, version control, caches.
IGNORED = shutil.ignore_patterns(".git", "build*", "out", "*.egg-info", "__pycache__")


class Block:
    def __init__(self, where, language, text, marker):
        self.where = where  # FILE:LINE of the opening fence
        self.language = language
        self.text = text
        self.marker = marker  # the readme-test comment above it, or ""


def ParseBlocks(path, name):
    """The fenced blocks of a Markdown file, each with the readme-test marker just above it."""
    lines = open(path, encoding="utf-8").read().split("\n")
    blocks = []
    i = 0
    while i < len(lines):
        opening = FENCE.match(lines[i])
        if not opening:
            i += 1
            continue
        indent, language = opening.group(1), opening.group(2)
        body = []
        j = i + 1
        while j < len(lines) and lines[j].strip() != "```":
            body.append(lines[j][len(indent):] if lines[j].startswith(indent) else lines[j])
            j += 1
        if j == len(lines):
            raise SystemExit(f"{name}:{i + 1}: a code block that is never closed")
        above = lines[i - 1] if i > 0 else ""
        marker = MARKER.match(above)
        blocks.append(Block(f"{name}:{i + 1}", language, "\n".join(body) + "\n", marker.group(1) if marker else ""))
        i = j + 1
    # A marker that no fence follows is a typo that would silently run (or skip) the wrong thing.
    for number, line in enumerate(lines, 1):
        if MARKER.match(line) and not (number < len(lines) and FENCE.match(lines[number])):
            raise SystemExit(f"{name}:{number}: a readme-test marker must stand on the line above a code fence")
    return blocks


def OutputMatches(expected, actual):
    """True when `actual` lines match `expected`, where a line "..." matches any run of lines."""
    memo = {}

    def Match(i, j):
        if (i, j) in memo:
            return memo[(i, j)]
        if i == len(expected):
            result = j == len(actual)
        elif expected[i].strip() == "...":
            result = any(Match(i + 1, k) for k in range(j, len(actual) + 1))
        else:
            result = j < len(actual) and expected[i] == actual[j] and Match(i + 1, j + 1)
        memo[(i, j)] = result
        return result

    return Match(0, 0)


def Lines(text):
    lines = [line.rstrip() for line in text.split("\n")]
    while lines and not lines[-1]:
        lines.pop()
    return lines


def Listing(root):
    """Every file below `root` (not following the build-release link), as relative paths."""
    found = set()
    for folder, folders, files in os.walk(root):
        folders[:] = [f for f in folders if not os.path.islink(os.path.join(folder, f))]
        for name in files:
            found.add(os.path.relpath(os.path.join(folder, name), root))
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--source-dir", required=True, help="the source tree (holds README.md)")
    parser.add_argument("--build-dir", required=True, help="the build whose app/imufit the examples run")
    parser.add_argument("--keep", action="store_true", help="keep the copy and the outputs")
    parser.add_argument("markdown", nargs="*", help="more Markdown files (relative to the source tree) to run after README.md")
    args = parser.parse_args()
    source = os.path.abspath(args.source_dir)
    build = os.path.abspath(args.build_dir)
    if not os.access(os.path.join(build, "app", "imufit"), os.X_OK):
        raise SystemExit(f"{build}/app/imufit: not built")

    blocks = []
    for name in ["README.md"] + args.markdown:
        blocks += ParseBlocks(os.path.join(source, name), name)
    work = tempfile.mkdtemp(prefix="imufit_readme_test_")
    clone = os.path.join(work, "clone")
    results = os.path.join(work, "results")
    temp = os.path.join(work, "tmp")  # mktemp's folder: the scratch folder is found and named by it
    os.makedirs(results)
    os.makedirs(temp)
    shutil.copytree(source, clone, ignore=IGNORED, symlinks=True)
    os.symlink(build, os.path.join(clone, "build-release"))
    before = Listing(clone)

    # One bash for all blocks, so that the README's set-up block holds for the ones after it.
    script = ["set -e -o pipefail", 'cd "$1"']
    run, checks, problems = [], [], []
    last_run = None
    for block in blocks:
        where = block.where
        keyword, _, argument = block.marker.partition(" ")
        if block.language != "sh":
            if keyword == "output":
                if last_run is not None:
                    checks.append((block, last_run))
            elif keyword:
                problems.append(f"{where}: readme-test: {block.marker}: only 'output' applies to a {block.language or 'plain'} block")
            continue
        if keyword == "skip":
            print(f"{where}: skipped {argument}")
            last_run = None
            continue
        if keyword == "needs":
            if not (shutil.which(argument) or os.path.exists(os.path.join(clone, argument))):
                print(f"{where}: skipped: needs {argument}, which is not here")
                last_run = None
                continue
        elif keyword == "exit":
            if not argument.isdigit():
                problems.append(f"{where}: readme-test: exit needs a status: {block.marker}")
                continue
        elif keyword:
            problems.append(f"{where}: readme-test: {block.marker}: not skip, exit N, needs WHAT or output")
            continue
        n = len(run)
        run.append((block, int(argument) if keyword == "exit" else 0))
        last_run = n
        redirect = f'>"{results}/out.{n}" 2>"{results}/err.{n}"'
        script.append(f"# {where}")
        if keyword == "exit":
            script.append("set +e")
            script.append("{\n" + block.text + "} " + redirect)
            script.append(f'echo $? >"{results}/status.{n}"')
            script.append("set -e")
        else:
            script.append("{\n" + block.text + "} " + redirect)
            script.append(f'echo 0 >"{results}/status.{n}"')
        script.append(f'printf %s "${{scratch-}}" >"{results}/scratch.{n}"')
    if problems:
        print("\n".join(problems))
        return 1

    script_path = os.path.join(work, "readme.sh")
    with open(script_path, "w") as f:
        f.write("\n".join(script) + "\n")
    environment = dict(os.environ, TMPDIR=temp, LC_ALL="C")
    started = time.monotonic()
    finished = subprocess.run(["bash", script_path, clone], env=environment, stdin=subprocess.DEVNULL)
    seconds = time.monotonic() - started

    failures = []
    outputs = {}
    for n, (block, expected_status) in enumerate(run):
        where = block.where
        read = lambda kind: open(os.path.join(results, f"{kind}.{n}"), errors="replace").read()
        if not os.path.exists(os.path.join(results, f"out.{n}")):
            break  # the script stopped before this block
        status_file = os.path.join(results, f"status.{n}")
        status = int(read("status")) if os.path.exists(status_file) else finished.returncode
        scratch = read("scratch") if os.path.exists(os.path.join(results, f"scratch.{n}")) else ""
        out = read("out")
        outputs[n] = out.replace(scratch, "$scratch") if scratch else out
        print(f"--- {where}: exit {status}\n{out}{read('err')}", end="")
        if status != expected_status:
            failures.append(f"{where}: the block exited with status {status}, not {expected_status}")
    ran = len(outputs)
    if ran < len(run) and not failures:
        failures.append(f"{run[ran][0].where}: never reached (bash stopped with status {finished.returncode})")
    for block, n in checks:
        if n not in outputs:
            continue
        expected = Lines(block.text)
        actual = Lines(outputs[n])
        if not OutputMatches(expected, actual):
            diff = "\n".join(difflib.unified_diff(expected, actual, "quoted", "printed", lineterm=""))
            failures.append(f"{block.where}: the quoted output is not what {run[n][0].where} prints:\n{diff}")
    written = sorted(Listing(clone) - before)
    if written:
        failures.append("the examples wrote into the clone (use the scratch folder): " + ", ".join(written[:10]))

    print(f"=== {ran} of {len(run)} blocks run in {seconds:.1f} s, {len(checks)} quoted outputs checked")
    if failures:
        print("\n".join(failures))
        print(f"(the copy and the outputs are kept in {work})")
        return 1
    if not args.keep:
        shutil.rmtree(work)
    return 0


if __name__ == "__main__":
    sys.exit(main())
