"""The size limits of the brief, on every hand-written library source: no file over 500 lines,
no function over 150 (tests and the generated stub _core.pyi excepted).

C++ functions are found by their layout (clang-format's: a definition starts at column 0, or
at 2 inside a class, with its opening brace at the end of the line, and ends at the matching
closing brace at the same indent); Python functions by ast."""
import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
MAX_FILE_LINES = 500
MAX_FUNCTION_LINES = 150
NOT_A_FUNCTION = re.compile(
    r"\s*(namespace|struct|class|enum|extern|union|if|for|while|else|switch|do|case|try|catch|return|"
    r"template\s*<[^>]*>\s*(struct|class))\b|.*[=,(]\s*\{$|.*\[.*\]\s*\(.*\)\s*(mutable\s*)?(->.*)?\{$")


def _cpp_sources():
    for base in ("include", "src", "python/bindings"):
        yield from sorted(p for p in (ROOT / base).rglob("*") if p.suffix in (".cpp", ".hpp"))


def _py_sources():
    yield from sorted((ROOT / "python" / "rotacal").rglob("*.py"))


def cpp_functions(text: str):
    """(first line, number of lines) of each function definition at indent 0 or 2."""
    lines = text.splitlines()
    for indent in ("", "  "):
        start = None
        for i, line in enumerate(lines):
            if start is None:
                body = line[len(indent):]
                if (line.startswith(indent) and body[:1] not in (" ", "") and line.rstrip().endswith("{")
                        and not NOT_A_FUNCTION.match(line) and not body.startswith(("#", "//"))):
                    start = i
            elif line in (indent + "}", indent + "};") or (indent and line and not line[0].isspace()):
                yield start + 1, i - start + 1
                start = None


def test_the_function_finder_sees_a_long_function():
    body = "\n".join(f"  x += {k};" for k in range(200))
    text = f"namespace rotacal {{\n\nint f(int x) {{\n{body}\n  return x;\n}}\n\n}}  // namespace rotacal\n"
    assert [n for _, n in cpp_functions(text)] == [203]


def test_no_source_file_is_over_500_lines():
    long = [f"{p.relative_to(ROOT)}: {n}" for p in [*_cpp_sources(), *_py_sources()]
            for n in [len(p.read_text().splitlines())] if n > MAX_FILE_LINES]
    assert not long, long


def test_no_function_is_over_150_lines():
    long = []
    for p in _cpp_sources():
        long += [f"{p.relative_to(ROOT)}:{s}: {n} lines" for s, n in cpp_functions(p.read_text())
                 if n > MAX_FUNCTION_LINES]
    for p in _py_sources():
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_FUNCTION_LINES:
                    long.append(f"{p.relative_to(ROOT)}:{node.lineno}: def {node.name}, {n} lines")
    assert not long, long
