"""The package's layout: every import goes downward (a module uses its own area and the
ones below it), and a wheel installs every folder of modules.

    ara's shared modules (errors, provenance, run_store, ...)
      <- grammars <- data <- eval/translate (the translator)
      <- eval (the F/P/C harness), training, coordination (side by side, not each other)
      <- ara.api, ara.cli, ara.demo (and each area's ``cli`` module, which wires commands)

So the language core can be read without the data, the translator without the
experiments, and a change to the harness cannot reach what ``ara translate`` does.
"""

import ast
from pathlib import Path

import pytest

tomllib = pytest.importorskip("tomllib", reason="reads pyproject.toml with Python 3.11's tomllib")

ROOT = Path(__file__).parents[1]
#: What setuptools installs: ``packages`` and the folder of each (``package-dir``).
SETUPTOOLS = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
#: Each top-level folder and the subpackage of ``ara`` it installs as.
FOLDERS = {folder: package for package, folder in SETUPTOOLS["package-dir"].items()}
#: (prefix, area, level), most specific prefix first.
AREAS = [("ara.grammars", "grammars", 1), ("ara.data", "data", 2),
         ("ara.eval.translate", "translate", 3), ("ara.eval", "eval", 4),
         ("ara.training", "training", 4), ("ara.coordination", "coordination", 4),
         ("ara.api", "product", 5), ("ara.cli", "product", 5), ("ara.demo", "product", 5)]


def area(module: str) -> tuple[str, int]:
    for prefix, name, level in AREAS:
        if module == prefix or module.startswith(prefix + "."):
            return name, level
    return "shared", 0


def module_name(path: Path, root: Path = ROOT) -> str:
    folder, *rest = path.relative_to(root).with_suffix("").parts
    return ".".join([FOLDERS[folder], *(p for p in rest if p != "__init__")])


def imports(path: Path) -> set[str]:
    """Every ``ara`` module ``path`` imports, in functions too; ``from ara import api`` is
    the module ``ara.api``."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module == "ara":
            found.update(f"ara.{alias.name}" for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            found.add(node.module)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    return {name for name in found if name == "ara" or name.startswith("ara.")}


def upward_imports(root: Path = ROOT) -> list[str]:
    wrong = []
    for folder in FOLDERS:
        for path in sorted((root / folder).rglob("*.py")):
            module = module_name(path, root)
            # Commands wire every area below the product; ``import ara`` offers the API
            # lazily, as a facade.
            if module.endswith(".cli") or module == "ara":
                continue
            own, level = area(module)
            for name in sorted(imports(path)):
                other, other_level = area(name)
                if other_level > level or (other_level == level and other != own):
                    wrong.append(f"{module} ({own}) imports {name} ({other})")
    return sorted(wrong)


def test_every_import_goes_downward():
    assert not upward_imports(), "\n".join(upward_imports())


def test_the_check_sees_an_upward_import(tmp_path):
    for name, text in {"grammars/ast.py": "from ara.errors import AraError\n",
                       "eval/translate/repair.py": "from ara.eval.harness import judge\n",
                       "eval/harness.py": "from ara.eval.translate import repair\n",
                       "training/recipe.py": "import ara.coordination.world\n",
                       "data/store.py": "def f():\n    from ara import demo\n",
                       "data/cli.py": "from ara.api import translate\n"}.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    assert upward_imports(tmp_path) == [
        "ara.data.store (data) imports ara.demo (product)",
        "ara.eval.translate.repair (translate) imports ara.eval.harness (eval)",
        "ara.training.recipe (training) imports ara.coordination.world (coordination)"]


def test_a_wheel_installs_every_python_folder():
    """setuptools installs only the packages pyproject lists: a folder of modules left
    out imports in a checkout (editable) and is missing from a wheel."""
    listed, needed = set(SETUPTOOLS["packages"]), set()
    for package, folder in SETUPTOOLS["package-dir"].items():
        for init in (ROOT / folder).rglob("*.py"):
            inside = init.parent.relative_to(ROOT / folder).parts
            if "prepared" not in inside and not inside[:1] == ("models",):
                needed.add(".".join([package, *inside]))
    assert needed <= listed, f"add to [tool.setuptools] packages: {sorted(needed - listed)}"
