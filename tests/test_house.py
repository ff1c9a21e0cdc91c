"""The house: every documented path imports, no import cycle between the package's modules."""

import ast
import importlib
import re
import sys
import types
from pathlib import Path

import pytest

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
    assert callable(
        importlib.import_module("discovery.vibroimpact.verify.criteria_landscape").landscape
    )
    for name in ("chart", "discover", "explain", "verify"):  # Ueda's, as the README documents
        assert callable(getattr(importlib.import_module("discovery.ueda"), name)), name
    from discovery.vibroimpact.verify import verify

    assert callable(verify)


def _modules(*packages):
    """Every module (not package) of ``packages``, as ``(dotted name, path)``."""
    for pkg in packages:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            if path.name != "__init__.py":
                yield _module_name(path), path


def _exported_here(package, name, module):
    """Whether ``package`` exports ``name`` defined in ``module``: a lazy package's
    ``_EXPORTS`` names the module; an eager one's ``__all__`` (checked for the parent)."""
    pkg = importlib.import_module(package)
    exports = getattr(pkg, "_EXPORTS", None)
    if exports is not None and name in exports:
        return f"{package}.{exports[name]}" == module
    return package == module.rpartition(".")[0] and name in getattr(pkg, "__all__", ())


def test_no_module_is_named_like_a_public_name_it_defines():
    """A module is named for what it holds, never like a function or class it defines that a
    package exports: importing ``pkg.chart`` would replace ``pkg.chart`` the function by the
    module, and ``import pkg.chart as m`` would give the function (``regime_chart``
    defines ``chart``)."""
    bad = []
    for name, path in _modules(*PACKAGES):
        stem = path.stem
        if stem.startswith("_"):
            continue
        tree = ast.parse(path.read_text())
        defined = {
            n.name
            for n in tree.body
            if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))
        }
        if stem not in defined:
            continue
        parts = name.split(".")
        owners = [".".join(parts[:i]) for i in range(len(parts) - 1, 0, -1)]
        bad += [
            f"{name} ({owner} exports {stem})"
            for owner in owners
            if _exported_here(owner, stem, name)
        ]
    assert not bad, bad


@pytest.mark.parametrize("package", PACKAGES)
def test_every_submodule_imports_as_a_module(package):
    """``import pkg.sub.mod as m`` gives the module for every module of the project (no
    public name of a package hides a module of the same name)."""
    bad = []
    for name, _ in _modules(package):
        ns = {}
        exec(f"import {name} as m", ns)
        if not isinstance(ns["m"], types.ModuleType) or ns["m"] is not sys.modules[name]:
            bad.append(f"{name} -> {ns['m']!r}")
    assert not bad, bad


def test_a_lazy_package_refuses_a_name_its_module_shares(tmp_path, monkeypatch):
    """``lazy_package`` raises at import when an export is named like its module."""
    pkg = tmp_path / "vidi_shadow_pkg"
    pkg.mkdir()
    (pkg / "thing.py").write_text("def thing():\n    return 1\n")
    (pkg / "__init__.py").write_text(
        "from discovery._startup._lazy import lazy_package\n"
        "lazy_package(__name__, {'thing': 'thing'})\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "vidi_shadow_pkg", raising=False)
    with pytest.raises(ImportError, match="'thing' \\(from .thing\\).*rename the module"):
        importlib.import_module("vidi_shadow_pkg")


def test_the_fit_and_the_loop_share_one_residual_problem():
    """The missing-effect loop's residual problem is the fit's (one problem, not two)."""
    loop = importlib.import_module("discovery.vibroimpact.explain.loop")
    fit_problem = importlib.import_module("discovery.vibroimpact.fit.problem")
    assert loop._Problem is fit_problem.ModelProblem
    pkg = importlib.import_module("discovery.vibroimpact.explain")
    assert loop.explain is pkg.explain


def test_split_study_and_impulse_modules_keep_their_public_names():
    """``studies/driver.py`` and ``data/impulse.py`` are split by job; every name of their
    ``__all__`` is still there, a moved one the same object as in its new module."""
    for old_mod, moved in {
        "studies.driver": {"result": ("StudyResult",), "run_files": ("code_version",)},
        "data.impulse": {
            "noise": ("estimate_noise",),
            "periods": ("own_period", "check_drive_period"),
        },
    }.items():
        split = importlib.import_module(f"discovery.vibroimpact.{old_mod}")
        assert all(hasattr(split, n) for n in split.__all__), old_mod
        package = old_mod.rpartition(".")[0]
        for mod, names in moved.items():
            new = importlib.import_module(f"discovery.vibroimpact.{package}.{mod}")
            for n in names:
                assert n in split.__all__ and getattr(split, n) is getattr(new, n), n


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


def _sklearn_constructors(tree):
    """The ``__init__`` nodes of scikit-learn estimators (classes deriving ``BaseEstimator``)."""
    out = set()
    for cls in ast.walk(tree):
        if isinstance(cls, ast.ClassDef) and any(
            "BaseEstimator" in ast.unparse(b) for b in cls.bases
        ):
            out |= {f for f in cls.body if isinstance(f, ast.FunctionDef) and f.name == "__init__"}
    return out


def test_functions_take_few_parameters():
    """No function of the package takes more than 8 parameters, nor more than 5
    positionally (``self``/``cls``, ``*args`` and ``**kwargs`` aside): a longer list is state
    that deserves a named object (a public function's options are a settings object,
    :mod:`discovery._api._settings`).  Exempt: the compiled kernels, and a scikit-learn
    estimator's ``__init__``, whose contract is every hyper-parameter an explicit keyword
    of the constructor (``get_params``, ``set_params``, ``clone``)."""
    wide = []
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            tree = ast.parse(path.read_text())
            exempt = _sklearn_constructors(tree)
            for node in ast.walk(tree):
                if not isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                    continue
                if node in exempt or _compiled(node):
                    continue
                a = node.args
                positional = [x for x in a.posonlyargs + a.args if x.arg not in ("self", "cls")]
                n = len(positional) + len(a.kwonlyargs)
                if n > 8 or len(positional) > 5:
                    where = f"{path.relative_to(ROOT)}:{node.lineno} {node.name}"
                    wide.append(f"{where} ({n} parameters, {len(positional)} positional)")
    assert not wide, wide


def test_modules_are_short():
    """No module of the package is over 700 lines, the compiled kernels included (the
    vibro-impact kernel is a package of modules, one per part): a longer module holds
    several jobs that deserve modules of their own."""
    long = []
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            n = len(path.read_text().splitlines())
            if n > 700:
                long.append(f"{path.relative_to(ROOT)} ({n})")
    assert not long, long


def test_the_compiled_kernels_functions_take_bundles():
    """No function of the compiled kernels (the vibro-impact kernel, Ueda's oscillators, the
    shared Dormand-Prince blocks) takes more than 12 parameters: their arrays travel in
    tuples (the law, the step control, the outputs, the work arrays), so that no caller
    writes a long call out (numba passes a tuple's fields as arguments)."""
    wide = []
    paths = sorted((ROOT / "discovery/vibroimpact/dynamics/kernel").glob("*.py")) + [
        ROOT / "discovery/ueda/_kernel.py",
        ROOT / "discovery/numerics/_dopri.py",
    ]
    for path in paths:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef) and len(node.args.args) > 12:
                wide.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name}")
    assert not wide, wide


def _graph():
    """Every module of the project -> the project modules its source imports (anywhere:
    top level or in functions), package ``__init__`` files included."""
    graph = {}
    for pkg in PACKAGES:
        for path in (ROOT / pkg).rglob("*.py"):
            name = _module_name(path)
            graph[name] = _imports(path, name)
    return graph


def _parents(mod):
    """The packages whose ``__init__`` runs when ``mod`` is imported."""
    parts = mod.split(".")
    return {".".join(parts[:i]) for i in range(1, len(parts))}


def _closure(graph, start):
    """Every project module that importing ``start`` may import, directly or through
    others (importing ``a.b.c`` runs ``a`` and ``a.b`` too)."""
    seen, todo = set(), [start]
    while todo:
        m = todo.pop()
        for dep in graph.get(m, set()) | _parents(m):
            if dep not in seen:
                seen.add(dep)
                todo.append(dep)
    seen.discard(start)
    return seen


def _modules_in(graph, pkg):
    return sorted(m for m in graph if m == pkg or m.startswith(pkg + "."))


def _crossings(graph, pkgs, forbidden):
    """``module -> forbidden modules it may import`` for every module of ``pkgs``."""
    out = {}
    for pkg in pkgs:
        for m in _modules_in(graph, pkg):
            bad = sorted(d for d in _closure(graph, m) if d.startswith(forbidden))
            if bad:
                out[m] = bad
    return out


def test_the_import_graph_follows_imports_through_other_modules():
    """The graph the layer tests walk: a module reaches what its imports import."""
    graph = _graph()
    assert "discovery.vibroimpact.dynamics.steady_states" in _closure(
        graph, "discovery.vibroimpact.verify.evaluation"
    )
    reach = _closure(graph, "discovery.warm")
    assert "discovery.ueda.exponents" in reach and "discovery.vibroimpact.dynamics" in reach
    assert "discovery" in _closure(graph, "discovery.numerics.executor")  # its packages


def test_two_systems_on_a_shared_floor():
    """The layout's rules, even through other modules: the shared floor imports neither
    system (nor what imports them: the warm-up, the CLI, the reports), neither system
    imports the other, and the vibro-impact data layer does not simulate."""
    graph = _graph()
    systems = ("discovery.vibroimpact", "discovery.ueda")
    above = ("discovery.warm", "discovery.parallel", "discovery.cli", "discovery.reporting")
    assert not _crossings(graph, ["discovery.numerics"], systems + above + ("reports",))
    assert not _crossings(graph, ["discovery.ueda"], ("discovery.vibroimpact",))
    assert not _crossings(graph, ["discovery.vibroimpact"], ("discovery.ueda",))
    assert not _crossings(
        graph, ["discovery.vibroimpact.data"], ("discovery.vibroimpact.dynamics",)
    )


def test_the_package_root_holds_its_public_layer():
    """The root of ``discovery`` shows the public layer at a glance: its modules are public
    (no ``_`` name), and the private infrastructure lives in private packages by job
    (``_api``: results, settings, checks, printing, progress; ``_files``: files in and out;
    ``_startup``: lazy names, the compiled kernels' cache). Their ``__init__`` files import
    nothing; none of them reaches a system, the shared floor or a layer above, and the file
    and start-up layers do not reach the API's machinery."""
    private = sorted(p.name for p in (ROOT / "discovery").glob("_*.py") if p.name != "__init__.py")
    assert not private, private
    graph = _graph()
    layers = ["discovery._api", "discovery._files", "discovery._startup"]
    assert all((ROOT.joinpath(*p.split(".")) / "__init__.py").is_file() for p in layers)
    assert not [p for p in layers if graph[p]], "a private package's __init__ imports"
    above = (
        "discovery.vibroimpact",
        "discovery.ueda",
        "discovery.numerics",
        "discovery.cli",
        "discovery.warm",
        "discovery.parallel",
        "discovery.reporting",
        "reports",
    )
    assert not _crossings(graph, layers, above)
    assert not _crossings(graph, ["discovery._files", "discovery._startup"], ("discovery._api",))


def test_the_package_draws_no_figures():
    """The systems (studies included) reach no report module: figures and documents are the
    report layer's, which the CLI calls (a study is handed its drawer)."""
    graph = _graph()
    pkgs = ["discovery.numerics", "discovery.vibroimpact", "discovery.ueda"]
    assert not _crossings(graph, pkgs, ("reports",))


def test_reports_and_the_package_do_not_import_each_other_in_a_cycle():
    """``discovery.report`` builds on ``reports``; nothing in ``reports`` reaches back to it
    (nor to the CLI), and the ``reports`` package itself imports nothing of ``discovery``."""
    graph = _graph()
    assert not _crossings(graph, ["reports"], ("discovery.reporting", "discovery.cli"))
    assert not {m for m in _closure(graph, "reports") if m.startswith("discovery")}


def _all_names(mod):
    """The module's ``__all__`` (statically), or None when it defines none."""
    p = ROOT.joinpath(*mod.split("."))
    path = p / "__init__.py" if (p / "__init__.py").is_file() else p.with_suffix(".py")
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets
        ):
            try:
                return set(ast.literal_eval(node.value))
            except ValueError:
                return None
    return None


def test_reports_use_the_packages_public_api_only():
    """``reports`` imports from ``discovery`` public modules only (no ``_`` in the path) and
    only the names those modules export (their ``__all__``)."""
    bad = []
    for path in sorted((ROOT / "reports").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                mods = [(a.name, None) for a in node.names]
            elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
                mods = [(node.module, [a.name for a in node.names])]
            else:
                continue
            for mod, names in mods:
                if mod.split(".")[0] != "discovery":
                    continue
                where = f"{path.relative_to(ROOT)}:{node.lineno} {mod}"
                if any(part.startswith("_") for part in mod.split(".")):
                    bad.append(f"{where} (a private module)")
                    continue
                exported = _all_names(mod)
                for n in names or ():
                    if n.startswith("_") or (exported is not None and n not in exported):
                        bad.append(f"{where}.{n} (not exported)")
    assert not bad, bad


def test_no_module_calls_a_private_method_of_another_modules_class():
    """A method named ``_x`` is called only in the module that defines it (``fit`` does not
    reach into explain's models): what other modules need gets a public name."""
    defined = {}  # private method name -> modules whose classes define it
    trees = {}
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            name = _module_name(path)
            trees[name] = tree = ast.parse(path.read_text())
            for cls in (n for n in ast.walk(tree) if isinstance(n, ast.ClassDef)):
                for f in cls.body:
                    if (
                        isinstance(f, ast.FunctionDef)
                        and f.name.startswith("_")
                        and not f.name.startswith("__")
                    ):
                        defined.setdefault(f.name, set()).add(name)
    bad = []
    for name, tree in trees.items():
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Call)
                and isinstance(node.func, ast.Attribute)
                and node.func.attr in defined
                and name not in defined[node.func.attr]
                and not (
                    isinstance(node.func.value, ast.Name) and node.func.value.id in ("self", "cls")
                )
            ):
                bad.append(f"{name}:{node.lineno} .{node.func.attr}()")
    assert not bad, bad


DOCS = ("README.md", *sorted(str(p.relative_to(ROOT)) for p in (ROOT / "docs").glob("*.md")))
_INLINE_IMPORT = re.compile(r"`((?:from\s+\S+\s+)?import\s+[^`]+)`")


def _doc_imports(text):
    """The import statements a document shows of this project: those in its ```python
    blocks and inline ones (`` `from discovery import a, b` ``), as AST nodes."""
    sources = re.findall(r"```python\n(.*?)```", text, re.S)
    sources += _INLINE_IMPORT.findall(text)
    out = []
    for src in sources:
        lines = [ln for ln in src.splitlines() if re.match(r"\s*(from|import)\s", ln)]
        for line in lines:
            line = line.strip().rstrip(",").replace(", ...", "").replace("...", "")
            try:
                tree = ast.parse(line.split("#")[0].strip().rstrip(","))
            except SyntaxError:  # an import continued on the next lines: the block decides
                continue
            out += [
                n
                for n in tree.body
                if isinstance(n, ast.Import | ast.ImportFrom)
                and (n.module if isinstance(n, ast.ImportFrom) else n.names[0].name).split(".")[0]
                in PACKAGES
            ]
        try:
            tree = ast.parse(src)
        except SyntaxError:
            continue
        out += [
            n
            for n in ast.walk(tree)
            if isinstance(n, ast.ImportFrom) and (n.module or "").split(".")[0] in PACKAGES
        ]
    return out


def _alias_paths(text):
    """``package.attr`` for each ``alias.attr`` a ```python block uses after ``import package
    as alias`` (``d.discover`` after ``import discovery as d``)."""
    out = set()
    for src in re.findall(r"```python\n(.*?)```", text, re.S):
        try:
            tree = ast.parse(src)
        except SyntaxError:
            continue
        alias = {
            a.asname or a.name: a.name
            for n in ast.walk(tree)
            if isinstance(n, ast.Import)
            for a in n.names
            if a.name.split(".")[0] in PACKAGES
        }
        out |= {
            f"{alias[n.value.id]}.{n.attr}"
            for n in ast.walk(tree)
            if isinstance(n, ast.Attribute)
            and isinstance(n.value, ast.Name)
            and n.value.id in alias
        }
    return out


def test_every_import_the_docs_show_resolves():
    """Each ``import`` / ``from ... import`` the README and docs/ show (code blocks and inline)
    imports, and each dotted path they name in backticks or use through an imported alias
    resolves."""
    bad, seen = [], 0
    for doc in DOCS:
        text = (ROOT / doc).read_text()
        nodes = {ast.unparse(n): n for n in _doc_imports(text)}
        for node in nodes.values():
            seen += 1
            try:
                if isinstance(node, ast.Import):
                    for a in node.names:
                        importlib.import_module(a.name)
                else:
                    mod = importlib.import_module(node.module)
                    for a in node.names:
                        getattr(mod, a.name)
            except (ImportError, AttributeError) as exc:
                bad.append(f"{doc}: {ast.unparse(node)} ({exc})")
        named = set(re.findall(r"`((?:discovery|reports|constraints)(?:\.[A-Za-z_]\w*)+)", text))
        for p in sorted(named | _alias_paths(text)):
            seen += 1
            try:
                _resolve(p)
            except (ImportError, AttributeError) as exc:
                bad.append(f"{doc}: {p} ({exc})")
    assert seen >= 60, seen
    assert not bad, bad
