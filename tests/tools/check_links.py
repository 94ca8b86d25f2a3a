#!/usr/bin/env python3
"""Every relative link and every repository path that README.md and docs/*.md name exists, and
every #anchor of a link to a Markdown file names one of its headings; every repository path a
comment in host/, capture/, shaders/, bench/ or tests/ names exists. Prints each one that does
not, and exits 1 if any.

Usage: check_links.py REPOSITORY_ROOT"""
import glob
import os
import re
import sys

TOP = ("host", "capture", "shaders", "tests", "bench", "scripts", "docs", "scenes", "cmake", ".ci")
PATH = re.compile(r"`((?:%s)/[A-Za-z0-9_./+-]+)`" % "|".join(re.escape(t) for t in TOP))
COMMENT_PATH = re.compile(r"(?<![\w/.])((?:%s)/[A-Za-z0-9_/+-]+\.[a-z]+)" % "|".join(re.escape(t) for t in TOP))
LINK = re.compile(r"\]\(([^)\s]+)\)")


def slug(heading):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"[`*_]", "", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(path):
    with open(path, encoding="utf-8") as f:
        return {slug(line.lstrip("#")) for line in f if line.startswith("#")}


def exists(root, path):
    path = path.rstrip(".,:;")
    return any(os.path.exists(p) for p in (os.path.join(root, path), os.path.join(root, path.rstrip("/"))))


def main():
    root = sys.argv[1]
    missing = []
    for doc in [os.path.join(root, "README.md")] + sorted(glob.glob(os.path.join(root, "docs", "*.md"))):
        text = open(doc, encoding="utf-8").read()
        name = os.path.relpath(doc, root)
        for target in LINK.findall(text):
            if re.match(r"[a-z]+:", target):
                continue  # http:, https:, mailto:
            file, _, anchor = target.partition("#")
            full = os.path.normpath(os.path.join(os.path.dirname(doc), file)) if file else doc
            if not os.path.exists(full):
                missing.append(f"{name}: link to {target}: no such file")
            elif anchor and full.endswith(".md") and anchor not in anchors(full):
                missing.append(f"{name}: link to {target}: no heading #{anchor}")
        for path in PATH.findall(text):
            if any(c in path for c in "*{<") or path.endswith("/NNNNN"):
                continue
            if not exists(root, path):
                missing.append(f"{name}: names {path}, which does not exist")
    for source in sorted(glob.glob(os.path.join(root, "**", "*"), recursive=True)):
        rel = os.path.relpath(source, root)
        if not rel.startswith(("host/", "capture/", "shaders/", "bench/", "tests/")) or os.path.isdir(source):
            continue
        if not rel.endswith((".cpp", ".hpp", ".h", ".comp", ".glsl", ".vert", ".frag", ".py")) or "/fixtures/" in rel:
            continue
        for number, line in enumerate(open(source, encoding="utf-8", errors="replace"), 1):
            comment = line.split("//", 1)[1] if "//" in line else (line.split("#", 1)[1] if rel.endswith(".py") and "#" in line else "")
            for path in COMMENT_PATH.findall(comment):
                if not exists(root, path):
                    missing.append(f"{rel}:{number}: names {path}, which does not exist")
    for m in missing:
        print(m)
    print(f"{len(missing)} missing")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
