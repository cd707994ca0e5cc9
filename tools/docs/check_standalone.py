#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""The repository stands on its own: no tracked file cites a document outside it (the
background notes STUDIES.md / MODELS.md, a sibling ../shared folder), an issue number of a
tracker a clone does not have, a dated diary entry ("re-voiced on 28 Nov 2026"), or a section
of one of its own docs that the doc does not have (`docs/x.md, "Title"`: the title must be in
that doc, a heading or a bold lead). History lives in CHANGELOG.md and docs/decisions/, which
may name what they replaced and when. Papers are cited by author, title and venue instead.

    check_standalone.py SOURCE_DIR    # exits 1 and lists every offending line
    check_standalone.py --self-test   # the checks find what they must, in a scratch repository
"""
import os
import re
import subprocess
import sys
import tempfile

PATTERNS = [
    (re.compile(r"\b(STUDIES|MODELS|STYLE)\.md\b"), "cites a background note outside the repository"),
    (re.compile(r"(\.\./shared/|/work/shared|\bshared/(data|docs|seeds)\b|(?<![\w/])data/published\b)"),
     "cites a folder outside the repository"),
    (re.compile(r"\b[Ii]ssues? #?\d+|\(#\d+\)|\bsee #\d+"), "cites an issue number"),
    (re.compile(r"\b\d{1,2} (Jan|Feb|Mar|Apr|May|Jun|Jul|Aug|Sep|Oct|Nov|Dec)[a-z]*\.? 20\d\d\b"),
     "dates a change (history goes in CHANGELOG.md and docs/decisions/)"),
]
ALLOWED_PREFIXES = ("CHANGELOG.md", "docs/decisions/", "LICENSE")
# A doc and the section cited after it, possibly across a comment's line break.
SECTION = re.compile(r'(docs/[\w./-]+\.md),?\s*"([A-Z][^"();=<>{}]{2,})"')
COMMENT_BREAK = re.compile(r"\n[ \t]*(#|//+|\*|;)?[ \t]*")


def normalised(text: str) -> str:
    return " ".join(text.replace("**", "").replace("`", "").split())


def section_problems(root: str, name: str, text: str, docs: dict) -> list:
    """Sections cited as `docs/x.md, "Title"` that x.md does not hold."""
    out = []
    joined = COMMENT_BREAK.sub(" ", text)
    for m in SECTION.finditer(joined):
        doc, title = m.group(1), normalised(m.group(2))
        if doc not in docs:
            try:
                with open(f"{root}/{doc}", encoding="utf-8") as f:
                    docs[doc] = normalised(f.read())
            except OSError:
                docs[doc] = None
        if docs[doc] is None:
            out.append(f"{name}: cites {doc}, which the repository does not hold")
        elif title not in docs[doc]:
            out.append(f'{name}: cites section "{title[:60]}" of {doc}, which it does not hold')
    return out
SELF = "tools/docs/check_standalone.py"


def problems_in(root: str) -> tuple:
    files = subprocess.run(["git", "-C", root, "ls-files", "-z"], capture_output=True,
                           check=True).stdout.decode("utf-8").split("\0")
    problems = []
    docs = {}
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
        problems += section_problems(root, name, text, docs)
    return problems, len(files)


def self_test() -> int:
    """A scratch repository with one line of each kind the checks must find, and lines they
    must let through."""
    files = {
        "docs/guide.md": "# Guide\n\n## The listener\n\n- **A bold lead.** Text.\n",
        "docs/decisions/old.md": "Re-voiced on 28 Nov 2026 (issue #12).\n",
        "a.toml": ("# see STUDIES.md\n"
                   "# set by hand on 28 Nov 2026\n"
                   "# fixed in issue #38\n"
                   "# target (issue 8): one block\n"
                   "# (docs/guide.md, \"A section it lacks\")\n"
                   "# (docs/missing.md, \"Anything\")\n"
                   "# fine: (docs/guide.md, \"The listener\") and (docs/guide.md,\n"
                   "# \"A bold lead\"), ISO dates 2026-11-28 and code (docs/guide.md\") x\n"),
    }
    want = ["a.toml:1: cites a background note", "a.toml:2: dates a change",
            "a.toml:3: cites an issue number", "a.toml:4: cites an issue number",
            'section "A section it lacks" of docs/guide.md',
            "cites docs/missing.md, which the repository does not hold"]
    with tempfile.TemporaryDirectory() as root:
        for name, text in files.items():
            os.makedirs(os.path.dirname(f"{root}/{name}") or root, exist_ok=True)
            with open(f"{root}/{name}", "w", encoding="utf-8") as f:
                f.write(text)
        subprocess.run(["git", "-C", root, "init", "-q"], check=True)
        subprocess.run(["git", "-C", root, "add", "."], check=True)
        found, _ = problems_in(root)
    missing = [w for w in want if not any(w in p for p in found)]
    extra = [p for p in found if not any(w in p for w in want)]
    for w in missing:
        print(f"self-test: not found: {w}")
    for p in extra:
        print(f"self-test: found but should not be: {p}")
    if missing or extra:
        return 1
    print(f"self-test ok: {len(found)} problems found, as expected")
    return 0


def main() -> int:
    if sys.argv[1:] == ["--self-test"]:
        return self_test()
    if len(sys.argv) != 2:
        print("usage: check_standalone.py SOURCE_DIR | --self-test", file=sys.stderr)
        return 2
    problems, count = problems_in(sys.argv[1])
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} line(s) tie the repository to documents it does not hold")
        return 1
    print(f"ok: {count} tracked files cite no outside document, issue number, date of a change "
          "or missing section")
    return 0


if __name__ == "__main__":
    sys.exit(main())
