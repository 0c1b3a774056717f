"""The code's shape: imports flow one way (no circle in solver/ or workflow/, counting imports
inside functions), and a flow is asked, not named: no comparison with a flow's name and no
mapping keyed by one outside the registry."""
import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = {"solver": ROOT / "solver", "study": ROOT / "workflow" / "study"}


def modules() -> dict[str, Path]:
    """Every module of our packages by its dotted name (a package by its own name)."""
    out = {}
    for pkg, folder in PACKAGES.items():
        for f in folder.rglob("*.py"):
            parts = [pkg, *f.relative_to(folder).with_suffix("").parts]
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = f
    return out


def imports(name: str, path: Path, known: set[str]) -> set[str]:
    """The modules of ours that ``name`` imports anywhere in its file (functions included)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")
                anchor = anchor[:len(anchor) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in node.names]
        else:
            continue
        for t in targets:
            while t and t not in known:  # "solver.x.y" -> the longest module of ours it names
                t = t.rpartition(".")[0]
            if t and t != name:
                found.add(t)
    return found


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in graph:
        if v not in index:
            visit(v)
    return out


def test_no_import_circle_in_solver_or_workflow():
    mods = modules()
    graph = {m: imports(m, p, set(mods)) for m, p in mods.items()}
    # a package's __init__ runs before its modules: an edge into a package is an edge into it
    assert cycles(graph) == []


def test_the_walk_sees_an_import_inside_a_function():
    """The import graph counts the imports inside functions (what the test above relies on)."""
    mods = modules()
    assert "study.flows.scene_figures" in imports("study.flows.scene", mods["study.flows.scene"], set(mods))


def test_no_flow_module_left_beside_the_registry():
    assert sorted(p.name for p in PACKAGES["study"].glob("flow*.py")) == []


def flow_names() -> set[str]:
    from study.registry import FLOWS
    return set(FLOWS)


def branches(tree: ast.AST, names: set[str]) -> list[ast.Constant]:
    """The flow names compared with (==, !=, in) or used as a dict key in ``tree``."""
    found = []
    for node in ast.walk(tree):
        consts = []
        if isinstance(node, ast.Compare):
            consts = [n for n in [node.left, *node.comparators] if isinstance(n, ast.Constant)]
            consts += [e for n in node.comparators if isinstance(n, (ast.Tuple, ast.List, ast.Set))
                       for e in n.elts if isinstance(e, ast.Constant)]
        elif isinstance(node, ast.Dict):
            consts = [k for k in node.keys if isinstance(k, ast.Constant)]
        found += [c for c in consts if c.value in names]
    return found


def test_no_code_outside_the_registry_branches_on_a_flows_name():
    """No comparison (==, !=, in) with a flow's name and no dict keyed by one, outside
    study/registry.py, in the study package; nor in the rules and the Snakefile."""
    names = flow_names()
    offences = []
    for name, path in modules().items():
        if name == "study.registry" or not name.startswith("study"):
            continue
        offences += [f"{path.relative_to(ROOT)}:{c.lineno} {c.value!r}"
                     for c in branches(ast.parse(path.read_text()), names)]
    pattern = re.compile(r"""(==|!=|\bin\b)\s*\(?\s*["'](%s)["']|["'](%s)["']\s*(==|!=|:)""" % (
        "|".join(names), "|".join(names)))
    for path in [ROOT / "Snakefile", *(ROOT / "workflow" / "rules").glob("*.smk")]:
        for k, line in enumerate(path.read_text().splitlines(), 1):
            if pattern.search(line):
                offences.append(f"{path.relative_to(ROOT)}:{k} {line.strip()}")
    assert offences == []


def test_the_branch_test_catches_a_branch():
    """The walk above flags each way of naming a flow, and not a name used otherwise."""
    tree = ast.parse('if cfg["flow"] == "slump":\n    pass\nx = {"film": 1}\ny = f in ("user", "x")\n'
                     'title = "the conveyor"\n')
    assert sorted(c.value for c in branches(tree, flow_names())) == ["film", "slump", "user"]
