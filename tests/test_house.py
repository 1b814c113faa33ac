"""The shape of the house (STYLE.md): small functions, no import circle, and family members named as strings only
inside their own families — so that the next physics is one file and a registry line, not a branch in ten places.
Static checks over the package's source: they cost milliseconds."""
from __future__ import annotations

import ast
import re
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent / "fretsim"
MAX_FUNCTION, MAX_CLASS = 80, 250  # lines, decorators excluded
# the bound.  Those that remain: plotting reads a results file's inputs (the wear law's and the cycle's names
# as written), uncertainty names a distribution `uniform`, validate loops over the sources of published values
# (`paper`, ...)
MAX_NAME_COMPARISONS = 12
# members of the families (cycle, stroke, wear law, stepping scheme, gap model) and the grid rule / error estimate
MEMBERS = ("uniform|coulomb|archard|energy|mid_stroke|resolved|bdf2|implicit|adaptive|linear|backward_euler|"
           "stroke_average|paper|companion")
NAME = rf"""['"]({MEMBERS})['"]"""
# `x == "name"`, `"name" != x`, and `x in ("a", "name", ...)` wherever the member stands in the tuple
COMPARISON = re.compile(rf"""(==|!=)\s*{NAME}|{NAME}\s*(==|!=)|\bin \((?:[^()]*?,\s*)?{NAME}""")


def _modules() -> dict:
    out = {}
    for path in PACKAGE.rglob("*.py"):
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def test_no_function_over_80_lines_and_no_class_over_250():
    long = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                size = node.end_lineno - node.lineno + 1
                if size > (MAX_CLASS if isinstance(node, ast.ClassDef) else MAX_FUNCTION):
                    long.append(f"{path.relative_to(PACKAGE.parent)}:{node.lineno} {node.name} ({size} lines)")
    assert not long, long


def _imports(modules: dict) -> dict:
    """Each module's fretsim imports, at module level and inside functions alike (a circle either way)."""
    def resolve(name: str) -> str:
        while name and name not in modules:
            name = name.rsplit(".", 1)[0] if "." in name else ""
        return name

    graph = {}
    for name, path in modules.items():
        deps = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                deps |= {resolve(a.name) for a in node.names}
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                subs = [resolve(f"{node.module}.{a.name}") for a in node.names]
                subs = [s for s in subs if s.startswith(node.module + ".")]  # `from package import module`
                deps |= set(subs) | ({resolve(node.module)} if len(subs) < len(node.names) else set())
        graph[name] = deps - {"", name}
    return graph


def test_no_import_circle():
    graph = _imports(_modules())
    circles, done = [], set()

    def visit(node, path):
        if node in path:
            circles.append(path[path.index(node):] + [node])
            return
        if node in done:
            return
        for dep in sorted(graph.get(node, ())):
            visit(dep, path + [node])
        done.add(node)

    for name in sorted(graph):
        visit(name, [])
    assert not circles, circles


def test_family_members_are_compared_as_strings_in_at_most_a_dozen_places():
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        text = path.read_text()
        for match in COMPARISON.finditer(text):
            line = text[:match.start()].count("\n") + 1
            found.append(f"{path.relative_to(PACKAGE.parent)}:{line}: {text.splitlines()[line - 1].strip()}")
    assert len(found) <= MAX_NAME_COMPARISONS, "\n".join(found)
