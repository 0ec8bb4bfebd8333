#!/usr/bin/env python3
"""The documentation as a whole (ctest docs_reachable): every page of docs/ can be reached from
README.md by following links, every relative link to a Markdown page names one that exists, and
every ```sh block of README.md and docs/*.md is run by readme_examples (its page is among the
pages named here, the ones tests/CMakeLists.txt gives readme_test.py) or is marked skipped with a
reason (<!-- readme-test: skip (why) -->, docs/development.md).

  python3 tests/docs_test.py --source-dir . docs/simulate.md docs/fit.md ...
"""

import argparse
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from readme_test import ParseBlocks  # noqa: E402  (the same blocks and markers readme_examples reads)

# [text](target) with a relative target ending in .md (an anchor after it allowed).
LINK = re.compile(r"\]\(([^)#\s:]+\.md)(?:#[^)]*)?\)")


def Links(source, page):
    """The Markdown pages `page` links to, relative to the source tree."""
    text = open(os.path.join(source, page), encoding="utf-8").read()
    folder = os.path.dirname(page)
    return [os.path.normpath(os.path.join(folder, target)) for target in LINK.findall(text)]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--source-dir", required=True, help="the source tree (holds README.md and docs/)")
    parser.add_argument("run", nargs="*", help="the pages readme_examples runs after README.md")
    args = parser.parse_args()
    source = os.path.abspath(args.source_dir)
    pages = sorted("docs/" + name for name in os.listdir(os.path.join(source, "docs")) if name.endswith(".md"))
    problems = []

    reached, todo = {"README.md"}, ["README.md"]
    while todo:
        page = todo.pop()
        for target in Links(source, page):
            if not os.path.exists(os.path.join(source, target)):
                problems.append(f"{page}: links to {target}, which does not exist")
            elif target not in reached:
                reached.add(target)
                todo.append(target)
    for page in pages:
        if page not in reached:
            problems.append(f"{page}: no page links to it (README.md, or a page reached from it, should)")

    run = {"README.md"} | set(args.run)
    for name in run:
        if not os.path.exists(os.path.join(source, name)):
            problems.append(f"{name}: named as run by readme_examples, but there is no such page")
    blocks = 0
    for page in ["README.md"] + pages:
        for block in ParseBlocks(os.path.join(source, page), page):
            if block.language != "sh":
                continue
            blocks += 1
            keyword, _, reason = block.marker.partition(" ")
            if keyword == "skip":
                if not re.fullmatch(r"\(.+\)", reason.strip()):
                    problems.append(f"{block.where}: skipped without a reason: <!-- readme-test: skip (why) -->")
            elif page not in run:
                problems.append(f"{block.where}: an sh example that readme_examples never runs: add {page} to "
                                "the pages of tests/CMakeLists.txt, or mark it <!-- readme-test: skip (why) -->")

    print(f"{len(pages)} pages of docs/, {len(reached) - 1} reached from README.md; {blocks} sh blocks, "
          f"{len(run)} pages run")
    if problems:
        print("\n".join(problems))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
