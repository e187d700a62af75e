"""Issue 35: README counts and names what the code has: the error classes (each named, and
their number in words), the environment variables the package reads, and the extras of
pyproject.toml."""
import inspect
import re
import tomllib
from pathlib import Path

import airgun_xl.errors as errors

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
WORDS = {9: "nine", 10: "ten", 11: "eleven", 12: "twelve", 13: "thirteen"}


def test_readme_names_and_counts_every_error_class():
    classes = sorted(name for name, obj in vars(errors).items()
                     if inspect.isclass(obj) and issubclass(obj, errors.AirgunXlError))
    assert len(classes) >= 10
    missing = [name for name in classes if not re.search(rf"`(airgun_xl\.)?{name}`", README)]
    assert missing == []
    assert f"All {WORDS[len(classes)]}, the base included," in README


def test_readme_names_every_environment_variable_the_package_reads():
    found = set()
    for path in (ROOT / "airgun_xl").rglob("*.py"):
        found |= set(re.findall(r"AIRGUN_XL_[A-Z_]+", path.read_text()))
    assert found >= {"AIRGUN_XL_ARCHIVE", "AIRGUN_XL_MEMORY", "AIRGUN_XL_PURE"}
    assert sorted(name for name in found if f"`{name}" not in README) == []


def test_readme_names_every_extra():
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"]
    assert sorted(name for name in extras if f"`{name}`" not in README) == []


def test_ci_runs_readmes_two_opening_commands_verbatim_and_last():
    """README opens with its two commands (set-up and fill, then the tests), and .ci/run ends
    with exactly those two lines, in that order."""
    blocks = re.findall(r"^```sh\n(.*?)^```", README, re.S | re.M)
    first, second = (block.strip() for block in blocks[:2])
    assert "\n" not in first and "\n" not in second
    assert first.endswith("airgun-xl fill templates/shot_a.xlsx")
    assert second.endswith("python -m pytest -n auto --dist loadfile")
    assert README.index(first) < README.index("## What it is")
    ci = [line for line in (ROOT / ".ci" / "run").read_text().splitlines()
          if line.strip() and not line.startswith("#")]
    assert ci[-2:] == [first, second]
