#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""Checks that every relative link and #anchor in README.md and docs/**/*.md resolves.

A link resolves when the file or folder it names exists (relative to the page) and, when it has
an #anchor into a Markdown page, that page has a heading (or an explicit <a id/name>) with that
anchor under GitHub's rules: the heading's text in lower case, with every character that is not
a letter, digit, space, hyphen or underscore removed, spaces turned into hyphens, and "-1",
"-2", ... appended to repeats. Web links (http, https, mailto) are not followed. Links inside
code blocks and inline code are not links. Exits 1 naming each broken link as page:line.

    python3 tools/docs/check_links.py [ROOT]
"""
from __future__ import annotations

import re
import sys
from pathlib import Path
from urllib.parse import unquote

LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]*)>?(?:\s+\"[^\"]*\")?\s*\)")
REFDEF = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*<?(\S+?)>?(?:\s+.*)?$")
HEADING = re.compile(r"^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$")
EXPLICIT = re.compile(r"<a\s+(?:[^>]*\s)?(?:id|name)\s*=\s*\"([^\"]+)\"", re.I)
FENCE = re.compile(r"^\s{0,3}(```+|~~~+)")


def prose_lines(text: str):
    """(line number, line) outside fenced code blocks, with inline code removed."""
    fence = None
    for number, line in enumerate(text.splitlines(), 1):
        m = FENCE.match(line)
        if m:
            marker = m.group(1)
            if fence is None:
                fence = marker[0] * len(marker)
                continue
            if marker.startswith(fence):
                fence = None
                continue
        if fence is None:
            yield number, re.sub(r"(`+)(?:(?!\1).)+?\1", "``", line)


def slug(heading: str) -> str:
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link's text only
    text = re.sub(r"<[^>]+>", "", text)  # inline HTML
    text = text.strip().lower()
    text = "".join(c for c in text if c.isalnum() or c in " -_")
    return text.replace(" ", "-")


def anchors(page: Path, cache: dict[Path, set[str]]) -> set[str]:
    if page not in cache:
        found: set[str] = set()
        seen: dict[str, int] = {}
        text = page.read_text(encoding="utf-8")
        fence = None
        for line in text.splitlines():
            m = FENCE.match(line)
            if m:
                marker = m.group(1)
                if fence is None:
                    fence = marker[0] * len(marker)
                elif marker.startswith(fence):
                    fence = None
                continue
            if fence is not None:
                continue
            h = HEADING.match(line)
            if h:
                base = slug(h.group(2))
                n = seen.get(base, 0)
                found.add(base if n == 0 else f"{base}-{n}")
                seen[base] = n + 1
            found.update(EXPLICIT.findall(line))
        cache[page] = found
    return cache[page]


def targets(text: str):
    for number, line in prose_lines(text):
        for m in LINK.finditer(line):
            yield number, m.group(1)
        m = REFDEF.match(line)
        if m:
            yield number, m.group(1)


def check(root: Path) -> list[str]:
    pages = [root / "README.md", *sorted((root / "docs").rglob("*.md"))]
    cache: dict[Path, set[str]] = {}
    broken = []
    for page in pages:
        if not page.is_file():
            continue
        text = page.read_text(encoding="utf-8")
        for number, target in targets(text):
            if not target or re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):
                continue  # a web link, mailto:, ...
            path_part, _, anchor = target.partition("#")
            dest = page if not path_part else (page.parent / unquote(path_part)).resolve()
            where = f"{page.relative_to(root)}:{number}: {target}"
            if not dest.exists():
                broken.append(f"{where}: no such file {dest.relative_to(root.resolve()) if dest.is_relative_to(root.resolve()) else dest}")
                continue
            if anchor and dest.is_file() and dest.suffix == ".md":
                if unquote(anchor) not in anchors(dest, cache):
                    broken.append(f"{where}: no heading with the anchor #{anchor} in "
                                  f"{dest.relative_to(root.resolve())}")
    return broken


def main() -> int:
    root = Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    broken = check(root)
    for b in broken:
        print(b)
    if broken:
        print(f"check_links: {len(broken)} broken link(s)")
        return 1
    print("check_links: every relative link and anchor resolves")
    return 0


if __name__ == "__main__":
    sys.exit(main())
