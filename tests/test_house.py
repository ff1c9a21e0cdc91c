"""The house: every documented path imports, no import cycle between the package's modules."""

import ast
import importlib
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("discovery", "constraints", "reports")


def _module_name(path):
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _imports(path, name):
    """Modules of this project that ``path`` imports anywhere (top level or in functions)."""
    tree = ast.parse(path.read_text())
    is_pkg = path.name == "__init__.py"
    base = name if is_pkg else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                parts = base.split(".")
                parent = ".".join(parts[: len(parts) - node.level + 1])
                mod = f"{parent}.{node.module}" if node.module else parent
            else:
                mod = node.module or ""
            if mod.split(".")[0] not in PACKAGES:
                continue
            for alias in node.names:  # `from . import x` may name a submodule
                sub = f"{mod}.{alias.name}"
                out.add(sub if _exists(sub) else mod)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.split(".")[0] in PACKAGES)
    return {m for m in out if _exists(m)}


def _exists(mod):
    p = ROOT.joinpath(*mod.split("."))
    return p.with_suffix(".py").is_file() or (p / "__init__.py").is_file()


def test_no_import_cycle_between_modules():
    """Imports only go down: no module imports (even inside a function) a module that
    imports it back, directly or through others. Package ``__init__`` files only re-export
    lazily and are left out."""
    graph = {}
    for pkg in PACKAGES:
        for path in (ROOT / pkg).rglob("*.py"):
            name = _module_name(path)
            if path.name == "__init__.py":
                continue
            graph[name] = {
                m
                for m in _imports(path, name)
                if not (ROOT.joinpath(*m.split(".")) / "__init__.py").is_file()
            }
    state, stack, cycles = {}, [], []

    def visit(n):
        state[n] = 1
        stack.append(n)
        for m in sorted(graph.get(n, ())):
            if state.get(m) == 1:
                cycles.append(stack[stack.index(m) :] + [m])
            elif m not in state:
                visit(m)
        stack.pop()
        state[n] = 2

    for n in sorted(graph):
        if n not in state:
            visit(n)
    assert not cycles, "import cycles: " + "; ".join(" -> ".join(c) for c in cycles[:5])


def _resolve(path):
    parts = path.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        for a in parts[i:]:
            obj = getattr(obj, a)
        return obj
    raise ImportError(path)


def test_every_path_the_readme_documents_imports():
    text = (ROOT / "README.md").read_text()
    paths = sorted(
        set(re.findall(r"`((?:discovery|reports|constraints)(?:\.[A-Za-z_]\w*)+)", text))
    )
    assert len(paths) >= 15
    bad = []
    for p in paths:
        try:
            _resolve(p)
        except (ImportError, AttributeError) as exc:
            bad.append(f"{p} ({exc})")
    assert not bad, bad


def test_public_names_are_what_the_docs_say():
    """The package's functions stay functions and its modules stay reachable as modules."""
    import discovery

    for name in ("explain", "landscape", "identify", "discover", "response", "study"):
        assert callable(getattr(discovery, name)), name
    assert importlib.import_module("discovery.vibroimpact.explain").EFFECTS
    assert callable(importlib.import_module("discovery.vibroimpact.verify.landscape").landscape)
    for name in ("chart", "discover", "explain", "verify"):  # Ueda's, as the README documents
        assert callable(getattr(importlib.import_module("discovery.ueda"), name)), name
    from discovery.vibroimpact.verify import verify

    assert callable(verify)


def test_figures_leave_the_users_backend_alone():
    """Drawing a report's figures neither loads pyplot nor switches matplotlib's backend (a
    notebook user's inline backend stays)."""
    import subprocess
    import sys

    code = (
        "import sys, matplotlib; matplotlib.use('svg'); "
        "import reports.vibroimpact.figures, reports.ueda.figures, reports.ueda.explain_figure, "
        "reports.vibroimpact.study_figures; "
        "from reports._mpl import subplots, save; import tempfile, os; "
        "fig, ax = subplots(figsize=(2, 2)); ax.plot([0, 1]); "
        "d = tempfile.mkdtemp(); save(fig, os.path.join(d, 'x')); "
        "assert matplotlib.get_backend() == 'svg', matplotlib.get_backend(); "
        "assert 'matplotlib.pyplot' not in sys.modules; print('ok')"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=120
    )
    assert out.stdout.strip() == "ok", out.stderr


def _code_lines(node):
    """Lines of a function without its docstring."""
    n = node.end_lineno - node.lineno + 1
    body = node.body
    if (
        body
        and isinstance(body[0], ast.Expr)
        and isinstance(body[0].value, ast.Constant)
        and isinstance(body[0].value.value, str)
    ):
        n -= body[0].end_lineno - body[0].lineno + 1
    return n


def _compiled(node):
    """Whether a function is a numba kernel (its decorator names ``njit``/``jit``)."""
    return any("jit" in ast.unparse(d) for d in node.decorator_list)


def test_functions_are_short():
    """No function of the package is over 100 lines (docstring excluded), the compiled
    kernels aside: a long function is several steps that deserve names."""
    long = []
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and not _compiled(node):
                    n = _code_lines(node)
                    if n > 100:
                        long.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name} ({n})")
    assert not long, long


def _package_imports(pkg):
    """Project modules imported anywhere in package ``pkg`` (a dotted name)."""
    out = set()
    for path in sorted(ROOT.joinpath(*pkg.split(".")).rglob("*.py")):
        out |= _imports(path, _module_name(path))
    return out


def test_two_systems_on_a_shared_floor():
    """The layout's rules: the shared numerics import neither system, neither system
    imports the other, and the vibro-impact data layer does not simulate."""
    floor = _package_imports("discovery.numerics")
    assert not {m for m in floor if m.startswith(("discovery.vibroimpact", "discovery.ueda"))}
    ueda = _package_imports("discovery.ueda")
    assert not {m for m in ueda if m.startswith("discovery.vibroimpact")}
    vi = _package_imports("discovery.vibroimpact")
    assert not {m for m in vi if m.startswith("discovery.ueda")}
    data = _package_imports("discovery.vibroimpact.data")
    assert not {m for m in data if m.startswith("discovery.vibroimpact.dynamics")}
