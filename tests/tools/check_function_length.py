#!/usr/bin/env python3
"""Checks that no function in host/, capture/ and bench/ runs past MAX_LINES lines, from the
first line of its signature to its closing brace (docs/design.md, "Style"): free functions,
member functions in or out of their class, constructors with their initialiser lists; a
lambda counts with the function it is in. Exit 1 names each."""
import os
import re
import sys

MAX_LINES = 60
CODE = re.compile(r'//[^\n]*|/\*.*?\*/|R"(\w*)\(.*?\)\1"|"(?:\\.|[^"\\\n])*"|\'(?:\\.|[^\'\\\n])*\'', re.S)
TYPE = re.compile(r"\b(namespace|struct|class|enum|union)\b[^()]*$")
INITIALISER = re.compile(r"(=|\breturn)\s*$|[\[(,]\s*$")  # `x = {`, `f({`: a value, not a body


def blank(match):
    return re.sub(r"[^\n]", " ", match.group(0))


def long_functions(text):
    code = CODE.sub(blank, text)
    found, stack = [], []  # stack: (kind, first line, head) of each open brace
    statement_start = 0    # where the text since the last ; { } outside a value begins
    values = 0             # open braces that are part of an expression (an initialiser, a lambda argument)
    line = 1
    for k, c in enumerate(code):
        if c == "\n":
            line += 1
        elif c == "{":
            head = code[statement_start:k]
            enclosing = stack[-1][0] if stack else "scope"
            if values or head.count("(") > head.count(")") or INITIALISER.search(head.rstrip()):
                stack.append(("value", line, head))
                values += 1
                continue
            if TYPE.search(head.replace("\n", " ")):
                kind = "scope"
            elif enclosing == "scope" and "(" in head:
                kind = "function"
            else:
                kind = "block"
            first = line - head.lstrip().count("\n") if kind == "function" else line
            stack.append((kind, first, head))
            statement_start = k + 1
        elif c == "}":
            kind, first, head = stack.pop() if stack else ("block", line, "")
            if kind == "value":
                values -= 1
                continue
            if kind == "function" and line - first + 1 > MAX_LINES:
                name = re.findall(r"([\w:~]+)\s*\(", head)
                found.append((first, line - first + 1, name[0] if name else "?"))
            statement_start = k + 1
        elif c == ";" and not values:
            statement_start = k + 1
    return found


def main(root):
    problems = 0
    for top in ("host", "capture", "bench"):
        for folder, _, names in os.walk(os.path.join(root, top)):
            for n in sorted(names):
                if n.endswith((".cpp", ".hpp")):
                    path = os.path.join(folder, n)
                    for first, length, name in long_functions(open(path, encoding="utf-8").read()):
                        print(f"{os.path.relpath(path, root)}:{first}: {name} is {length} lines, more than {MAX_LINES}")
                        problems += 1
    print(f"{problems} function(s) over {MAX_LINES} lines" if problems else f"no function over {MAX_LINES} lines")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")))
