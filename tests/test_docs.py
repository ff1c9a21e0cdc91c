"""The documentation site's examples and names stay true (README.md and docs/*.md).

- every ``from X import Y`` / ``import X`` line of a Python block resolves;
- every backticked dotted path ``discovery.X.Y`` (also ``reports``, ``constraints``) resolves;
- every Python block marked ``<!-- runnable -->`` runs as printed, in a directory holding
  the quickstart's record (``vidi simulate`` as the README prints it) and the ``examples/``;
  a long one on a small input, named in its marker (``<!-- runnable: A => B; C => D -->``:
  the text ``A`` replaced by ``B``, ...);
- every relative link and image of the pages exists;
- the docs' quickstart is the README's.
"""

import importlib
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
FENCE = re.compile(r"(<!-- runnable([^\n]*?)-->\s*)?```python\n(.*?)```", re.S)


def _small(marker, code):
    """``code`` on the small input its marker names (``: A => B; C => D``)."""
    for pair in (p for p in marker.lstrip(": ").split(";") if "=>" in p):  # else a comment
        old, new = (x.strip() for x in pair.split("=>"))
        assert old in code, f"the marker replaces {old!r}, which the block does not hold"
        code = code.replace(old, new)
    return code


def _blocks():
    """(page, runnable, code) of every Python block (a runnable one on its small input)."""
    out = []
    for page in PAGES:
        for m in FENCE.finditer(page.read_text()):
            runnable, code = bool(m.group(1)), m.group(3)
            if runnable and m.group(2).strip():
                code = _small(m.group(2), code)
            out.append((page.relative_to(ROOT).as_posix(), runnable, code))
    return out


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


def test_the_site_has_its_pages_and_python_examples():
    names = {p.name for p in PAGES}
    for page in ("index.md", "api.md", "cli.md", "validation.md", "architecture.md", "ueda.md"):
        assert page in names, page
    assert sum(r for _, r, _ in _blocks()) >= 2


def test_every_import_line_of_the_examples_resolves():
    bad = []
    for page, _, code in _blocks():
        for line in code.splitlines():
            if re.match(r"\s*(from \S+ import .+|import \S+)\s*(#.*)?$", line):
                try:
                    exec(line.split("#")[0].strip(), {})
                except Exception as exc:  # noqa: BLE001 - every failure is reported
                    bad.append(f"{page}: {line.strip()} ({exc!r})")
    assert not bad, bad


def test_every_documented_path_resolves():
    bad = []
    for page in PAGES:
        paths = set(
            re.findall(r"`((?:discovery|reports|constraints)(?:\.[A-Za-z_]\w*)+)", page.read_text())
        )
        for p in sorted(paths):
            try:
                _resolve(p)
            except (ImportError, AttributeError) as exc:
                bad.append(f"{page.name}: {p} ({exc})")
    assert not bad, bad


def test_every_relative_link_and_image_exists():
    bad = []
    for page in PAGES:
        for target in re.findall(r"\]\(([^)\s]+)\)", page.read_text()):
            if re.match(r"[a-z]+:", target) or target.startswith("#"):
                continue
            if not (page.parent / target.split("#")[0]).exists():
                bad.append(f"{page.name}: {target}")
    assert not bad, bad


def test_the_docs_quickstart_is_the_readmes():
    def bash_block(text, after):
        i = text.index(after)
        return re.search(r"```bash\n(.*?)```", text[i:], re.S).group(1)

    readme = bash_block((ROOT / "README.md").read_text(), "<!-- quickstart -->")
    docs = bash_block((ROOT / "docs" / "getting-started.md").read_text(), "## Quickstart")
    assert readme == docs


@pytest.fixture(scope="module")
def record_dir(tmp_path_factory):
    """A directory with the quickstart's record D.csv, made by its first line as printed."""
    text = (ROOT / "README.md").read_text()
    block = re.search(r"<!-- quickstart -->\s*```bash\n(.*?)```", text, re.S).group(1)
    first = next(ln for ln in block.splitlines() if ln.strip())
    argv = shlex.split(first)
    assert argv[:2] == ["vidi", "simulate"], first
    where = tmp_path_factory.mktemp("docs")
    vidi = Path(sys.executable).with_name("vidi")
    subprocess.run([str(vidi), *argv[1:]], cwd=where, check=True, capture_output=True)
    shutil.copytree(ROOT / "examples", where / "examples")
    return where


@pytest.mark.parametrize(
    "page,code",
    [(p, c) for p, r, c in _blocks() if r],
    ids=lambda v: v if isinstance(v, str) and v.endswith(".md") else "",
)
def test_the_runnable_examples_run_as_printed(page, code, record_dir, monkeypatch, capsys):
    monkeypatch.chdir(record_dir)
    exec(compile(code, page, "exec"), {"__name__": "__docs__"})
    assert capsys.readouterr().out.strip(), f"{page}: the example printed nothing"


def test_every_public_name_has_one_api_page():
    """Each name of ``discovery.__all__`` is documented on exactly one page of docs/api/
    (``discovery.CRITERIA`` in prose: its definitions live with the criteria)."""
    import discovery

    where = {}
    for page in sorted((ROOT / "docs" / "api").glob("*.md")):
        for name in re.findall(r"^\.\. auto\w+:: (\w+)", page.read_text(), re.M):
            where.setdefault(name, []).append(page.name)
        if "`discovery.CRITERIA`" in page.read_text():
            where.setdefault("CRITERIA", []).append(page.name)
    assert {n: p for n, p in where.items() if len(p) > 1} == {}
    assert sorted(where) == sorted(discovery.__all__)
