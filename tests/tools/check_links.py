#!/usr/bin/env python3
"""Every relative link and every repository path that README.md and docs/*.md name exists, and
every #anchor of a link to a Markdown file names one of its headings; every repository path a
comment in host/, capture/, shaders/, bench/ or tests/ names exists; every section a document
or a comment names by its quoted title (docs/physics.md, "The start") is a heading there. Prints each one that does
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
# A section named by its title: `docs/physics.md, "The start"`, `[physics.md](physics.md), "The start"`,
# or within a document `see "One frame"`.
QUOTED = re.compile(r'((?:docs/)?[a-z_]+\.md|README\.md)`?\)?,?\s+"([^"\n]+)"')
SEE = re.compile(r'\bsee "([^"\n]+)"')


def slug(heading):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to hyphens."""
    text = re.sub(r"[`*_]", "", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(path):
    with open(path, encoding="utf-8") as f:
        return {slug(line.lstrip("#")) for line in f if line.startswith("#")}


def titles(path):
    with open(path, encoding="utf-8") as f:
        return [re.sub(r"[`*]", "", line.lstrip("#").strip()) for line in f if line.startswith("#")]


def has_section(path, title):
    """A heading of `path` is `title` or begins with it ("The start" names "The start: a jittered lattice")."""
    title = re.sub(r"[`*]", "", title).strip()
    return any(t == title or t.startswith(title + ":") or t.startswith(title + " (") for t in titles(path))


def missing_sections(root, where, text, own_doc=None):
    """Each section `text` names by title that its document lacks."""
    out = []
    for doc, title in QUOTED.findall(text):
        doc_path = os.path.join(root, doc if "/" in doc or doc == "README.md" else os.path.join("docs", doc))
        if os.path.exists(doc_path) and not has_section(doc_path, title):
            out.append(f'{where}: names {doc}, "{title}", which has no such section')
    if own_doc:
        for title in SEE.findall(text):
            if not has_section(own_doc, title):
                out.append(f'{where}: says see "{title}", which {os.path.relpath(own_doc, root)} has no section of')
    return out


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
        missing += missing_sections(root, name, text, doc)
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
            missing += missing_sections(root, f"{rel}:{number}", comment)
    for m in missing:
        print(m)
    print(f"{len(missing)} missing")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
