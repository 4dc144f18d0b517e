# SPDX-License-Identifier: BSD-3-Clause
"""The size limits of the brief, on every hand-written library source: no file over 500 lines,
no function over 150 (tests and the generated stub _core.pyi excepted).

C++ functions are found by their braces, with comments and literals blanked: a brace opened at
namespace or class scope whose statement holds a parameter list is a function body (lambdas
inside count to their function); Python functions by ast."""

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
MAX_FILE_LINES = 500
MAX_FUNCTION_LINES = 150
# Over the limit today, to be split (each named with why it is not yet): the test fails when a
# listed function is split without being taken off this list, as when a new one grows too long.
# Empty since solve_joint (src/core/joint_fit.cpp) was split along its stages.
KNOWN_LONG: set = set()


def _cpp_sources():
    for base in ("include", "src", "python/bindings"):
        yield from sorted(p for p in (ROOT / base).rglob("*") if p.suffix in (".cpp", ".hpp"))


def _py_sources():
    yield from sorted((ROOT / "python" / "rotacal").rglob("*.py"))


def _blank_comments_and_literals(text: str) -> str:
    """The text with comments and string and character literals blanked, newlines kept."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i) or text.startswith("/*", i):
            j = text.find("\n", i) if text[i + 1] == "/" else text.find("*/", i + 2) + 2
            j = n if j < 2 else j
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text.startswith('R"', i) and (m := re.match(r'R"([^(]*)\(', text[i:])):
            j = text.find(")" + m.group(1) + '"', i) + len(m.group(1)) + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(" " * (j + 1 - i))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


SCOPE = re.compile(r"\b(namespace|class|struct|union)\b")


def cpp_functions(text: str):
    """(name, first line, number of lines) of each function body opened at namespace or class
    scope: its statement holds a parameter list, no `=` before it, and is not a class head."""
    s = "\n".join(
        "" if line.lstrip().startswith("#") else line
        for line in _blank_comments_and_literals(text).split("\n")
    )
    line_at = [0] * len(s)
    line = 1
    for i, ch in enumerate(s):
        line_at[i] = line
        line += ch == "\n"
    stack, start = [], 0
    for i, ch in enumerate(s):
        if ch not in ";{}":
            continue
        if ch == "{":
            stmt = s[start:i]
            kind = "other"
            if all(k == "scope" for k, _, _ in stack):
                if SCOPE.search(stmt) and not re.search(r"\)\s*[\w\s]*$", stmt):
                    kind = "scope"
                elif ")" in stmt and "=" not in stmt.split("(")[0]:
                    kind = "function"
            first = start + len(stmt) - len(stmt.lstrip())
            name = re.findall(r"([~\w]+)\s*\(", stmt.split("(")[0] + "(")
            stack.append((kind, line_at[min(first, i)], name[-1] if name else ""))
        elif ch == "}" and stack:
            kind, first_line, name = stack.pop()
            if kind == "function":
                yield name, first_line, line_at[i] - first_line + 1
        start = i + 1


def test_the_function_finder_sees_long_functions_and_only_functions():
    body = "\n".join(f"  x += {k};  // {{" for k in range(200))
    text = (
        f"namespace rotacal {{\n\ntemplate <typename T>\nint f(int x,\n      int y) {{\n{body}\n  return x;\n}}\n\n"
        'struct A : B {\n  int g() const {\n    const char* c = "}";\n    return 1;\n  }\n};\n'
        "const std::vector<int> table = {1, 2};\n}  // namespace rotacal\n"
    )
    assert list(cpp_functions(text)) == [("f", 3, 205), ("g", 210, 4)]


def test_no_source_file_is_over_500_lines():
    long = [
        f"{p.relative_to(ROOT)}: {n}"
        for p in [*_cpp_sources(), *_py_sources()]
        for n in [len(p.read_text().splitlines())]
        if n > MAX_FILE_LINES
    ]
    assert not long, long


def test_no_function_is_over_150_lines():
    long, known = [], set()
    for p in _cpp_sources():
        for name, first, n in cpp_functions(p.read_text()):
            if n > MAX_FUNCTION_LINES:
                where = str(p.relative_to(ROOT))
                if (where, name) in KNOWN_LONG:
                    known.add((where, name))
                else:
                    long.append(f"{where}:{first}: {name}, {n} lines")
    for p in _py_sources():
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_FUNCTION_LINES:
                    long.append(f"{p.relative_to(ROOT)}:{node.lineno}: def {node.name}, {n} lines")
    assert not long, long
    assert known == KNOWN_LONG, f"split, take off KNOWN_LONG: {sorted(KNOWN_LONG - known)}"
