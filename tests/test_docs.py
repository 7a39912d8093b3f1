"""The documentation site builds cleanly, every page is in its navigation, and the README stays a
front page whose links into docs/ hold."""
import importlib.util
import os
import re
import subprocess
import sys

import pytest

from conftest import REPO

DOCS = REPO / "docs"
README_MAX_LINES = 250
DOCS_EXTRA = "the 'docs' extra is not installed (pip install -e \".[docs]\")"


def _importable(module: str) -> bool:
    try:
        return importlib.util.find_spec(module) is not None
    except ModuleNotFoundError:   # its parent package is missing
        return False


def _require_docs_tools():
    missing = [module for module in ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python",
                                     "pymdownx", "latex2mathml")
               if not _importable(module)]
    if missing:
        pytest.skip(f"{DOCS_EXTRA}: {', '.join(missing)} not importable")


def _nav_pages(entry) -> list[str]:
    """Every page path in an mkdocs nav entry (a list, a {title: page or list} mapping, a path)."""
    if isinstance(entry, str):
        return [entry]
    if isinstance(entry, list):
        return [page for item in entry for page in _nav_pages(item)]
    if isinstance(entry, dict):
        return [page for value in entry.values() for page in _nav_pages(value)]
    return []


def _config() -> dict:
    yaml = pytest.importorskip("yaml", reason=f"{DOCS_EXTRA}: PyYAML (mkdocs' config reader) not importable")
    return yaml.safe_load((REPO / "mkdocs.yml").read_text(encoding="utf-8"))


def _slug(heading: str) -> str:
    """The anchor mkdocs (Python-Markdown's toc) gives a heading."""
    text = re.sub(r"[`*_]", "", heading).strip().lower()
    text = re.sub(r"[^\w\s-]", "", text)
    return re.sub(r"[-\s]+", "-", text).strip("-")


def test_mkdocs_builds_strict(tmp_path):
    _require_docs_tools()
    env = dict(os.environ, NO_MKDOCS_2_WARNING="1")
    run = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                         cwd=REPO, capture_output=True, text=True, env=env, timeout=600)
    assert run.returncode == 0, f"mkdocs build --strict failed:\n{run.stdout}\n{run.stderr}"
    assert (tmp_path / "site" / "index.html").exists()
    assert (tmp_path / "site" / "api" / "index.html").exists()
    _check_api_page((tmp_path / "site" / "api" / "index.html").read_text(encoding="utf-8"))
    for page in ("models", "numerics"):
        _check_equations(page, (tmp_path / "site" / page / "index.html").read_text(encoding="utf-8"))
    assert not list((tmp_path / "site").rglob("*.py")), "the docs' hooks are copied into the site"


API_OBJECTS = ("identification.fit", "identification.FitResult", "identification.analysis.compare.compare_models",
               "identification.analysis.compare.recommend", "identification.fitting.fleet.fit_many",
               "identification.forward.simulate.simulate", "identification.analysis.predict.predict", "identification.characterise",
               "identification.measured.kdyn_table.KdynTable", "identification.load_measurement", "identification.training_tests",
               "fmu_src.parameter_files.read_parameter_set", "fmu_src.parameter_files.save_parameters",
               "fmu_src.fmi.pythonfmu_package.build_fmu", "fmu_src.fmi.native.build.build_native_fmu",
               "fmu_src.model.definition.BushingModel",
               "fmu_src.model.registry.get_model")


def _check_api_page(html: str) -> None:
    """Each public object under its own heading, followed by its signature."""
    for name in API_OBJECTS:
        heading = re.search(rf'<h[2-5] id="{re.escape(name)}"[^>]*>.*?</h[2-5]>\s*(<div class="doc-signature)?', html, re.S)
        assert heading, f"the API reference has no heading for {name}"
        if not name.endswith(("FitResult", "KdynTable", "BushingModel")):   # functions: the signature follows
            assert heading.group(1), f"the API reference shows no signature under {name}'s heading"


def _check_equations(page: str, html: str) -> None:
    """The page's equations are MathML made at build time: no TeX left, no script from elsewhere."""
    assert html.count("<math") >= 20, f"{page}: its equations are not rendered"
    assert "\\(" not in html and "\\[" not in html, f"{page}: an equation is left as TeX"
    assert not re.search(r"<script[^>]+src=\"https?:", html), f"{page}: a script from the network"


def test_every_nav_page_exists_and_every_page_is_in_the_nav():
    config = _config()
    assert config["docs_dir"] == "docs"
    nav = _nav_pages(config["nav"])
    assert len(nav) == len(set(nav)), "a page is in the nav twice"
    missing = [page for page in nav if not (DOCS / page).is_file()]
    assert not missing, f"nav pages missing from docs/: {missing}"
    pages = sorted(path.relative_to(DOCS).as_posix() for path in DOCS.rglob("*.md"))
    assert sorted(nav) == pages, f"pages not in the nav: {sorted(set(pages) - set(nav))}"


def test_nav_is_grouped_with_models_before_identification():
    config = _config()
    sections = [next(iter(entry)) for entry in config["nav"]]
    assert sections == ["Getting started", "FMU", "Models", "Identification", "Reference", "Development"]
    assert _nav_pages(config["nav"]).index("models.md") < _nav_pages(config["nav"]).index("identification.md")
    plugins = [next(iter(p)) if isinstance(p, dict) else p for p in config["plugins"]]
    assert "search" in plugins and "mkdocstrings" in plugins


def test_mathml_hook_converts_inline_and_display_tex():
    _require_docs_tools()
    spec = importlib.util.spec_from_file_location("docs_mathml_hook", DOCS / "hooks" / "mathml.py")
    hook = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hook)

    class Page:
        class file:
            src_uri = "models.md"

    html = ('<p>a <span class="arithmatex">\\(x &lt; y\\)</span> b</p>'
            '<div class="arithmatex">\\[\n\\dot{z} = A \\dot{x}\n\\]</div>')
    out = hook.on_page_content(html, Page, None, None)
    assert out.count("<math") == 2 and 'display="block"' in out and "\\(" not in out
    assert "&#x0003C;" in out or "&lt;" in out   # the escaped < is read as <, written as MathML


def test_readme_is_a_front_page():
    lines = (REPO / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= README_MAX_LINES, f"README.md has {len(lines)} lines; move detail into docs/"


def test_readme_links_into_docs_hold():
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    links = re.findall(r"\]\((docs/[^)\s]+)\)", readme)
    assert links, "the README links into docs/"
    for link in links:
        path, _, anchor = link.partition("#")
        target = REPO / path
        assert target.is_file(), f"README links to {link}, which does not exist"
        if anchor:
            headings = re.findall(r"^#{1,6}\s+(.+?)\s*$", target.read_text(encoding="utf-8"), re.M)
            assert anchor in {_slug(h) for h in headings}, f"README links to {link}: no such heading in {path}"


def test_docs_and_readme_agree_on_the_interface_table_and_the_commands():
    """The FMU guide repeats the README's interface table, and the overview its two commands."""
    row = re.compile(r"^\| `\w+` \| (?:input|output|parameter|local) \|.*\|$", re.M)
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    assert row.findall((DOCS / "fmu.md").read_text(encoding="utf-8")) == row.findall(readme)

    def commands(text):
        return [line.strip() for line in text.splitlines() if line.startswith("    python3 -m venv")]

    assert commands((DOCS / "index.md").read_text(encoding="utf-8")) == commands(readme)


def test_readme_and_overview_list_every_extra():
    tomllib = pytest.importorskip("tomllib", reason="tomllib needs Python 3.11")
    extras = set(tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]["optional-dependencies"])
    extra_row = re.compile(r"^\| `([\w-]+)` \| [^|]+ \| [^|]+ \|$", re.M)
    for page in (REPO / "README.md", DOCS / "index.md"):
        assert set(extra_row.findall(page.read_text(encoding="utf-8"))) == extras, page.name
