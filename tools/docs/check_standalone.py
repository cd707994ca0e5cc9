#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The repository stands on its own: no tracked file cites a document outside it (the
background notes STUDIES.md / MODELS.md, a sibling ../shared folder) or an issue number of a
tracker a clone does not have. History lives in CHANGELOG.md and docs/decisions/, which may name
what they replaced. Papers are cited by author, title and venue instead.

    check_standalone.py SOURCE_DIR    # exits 1 and lists every offending line
"""
import re
import subprocess
import sys

PATTERNS = [
    (re.compile(r"\b(STUDIES|MODELS|STYLE)\.md\b"), "cites a background note outside the repository"),
    (re.compile(r"(\.\./shared/|/work/shared|\bshared/(data|docs|seeds)\b|(?<![\w/])data/published\b)"),
     "cites a folder outside the repository"),
    (re.compile(r"\b[Ii]ssue #\d+|\(#\d+\)|\bsee #\d+"), "cites an issue number"),
]
ALLOWED_PREFIXES = ("CHANGELOG.md", "docs/decisions/")
SELF = "tools/docs/check_standalone.py"


def main() -> int:
    if len(sys.argv) != 2:
        print("usage: check_standalone.py SOURCE_DIR", file=sys.stderr)
        return 2
    root = sys.argv[1]
    files = subprocess.run(["git", "-C", root, "ls-files", "-z"], capture_output=True,
                           check=True).stdout.decode("utf-8").split("\0")
    problems = []
    for name in files:
        if not name or name.startswith(ALLOWED_PREFIXES) or name == SELF:
            continue
        try:
            with open(f"{root}/{name}", "rb") as f:
                data = f.read()
        except (FileNotFoundError, IsADirectoryError):
            continue
        if b"\0" in data[:8192]:
            continue  # binary (SQLite corpora, audio)
        text = data.decode("utf-8", errors="replace")
        for number, line in enumerate(text.splitlines(), 1):
            for pattern, what in PATTERNS:
                if pattern.search(line):
                    problems.append(f"{name}:{number}: {what}: {line.strip()[:120]}")
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} line(s) tie the repository to documents it does not hold")
        return 1
    print(f"ok: {len(files)} tracked files cite no outside document or issue number")
    return 0


if __name__ == "__main__":
    sys.exit(main())
