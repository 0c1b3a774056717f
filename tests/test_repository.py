"""The repository reads as a product: a short user guide, docs that stay inside the tree,
configuration files with short headers, a small set of maintained benchmarks."""
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
MAX_HEADER = 8  # comment lines before a config or example file's first setting


def tracked(*patterns: str) -> list[Path]:
    out = subprocess.run(["git", "ls-files", *patterns], cwd=ROOT, capture_output=True, text=True)
    if out.returncode != 0:
        pytest.skip("not a git checkout")
    return [ROOT / p for p in out.stdout.split()]


def lines(paths) -> int:
    return sum(len(p.read_text().splitlines()) for p in paths if p.exists())


def test_readme_opens_with_the_two_commands_and_is_a_short_guide():
    text = (ROOT / "README.md").read_text().splitlines()
    assert len(text) <= 150
    commands = [line for line in text[:8] if line.startswith("python3 -m venv")]
    assert commands[0].endswith("snakemake --cores 2") and commands[1].endswith("python -m pytest -q")


def test_markdown_stays_a_quarter_of_the_code_and_points_nowhere_outside():
    md = tracked("*.md")
    assert lines(md) <= 0.25 * lines(tracked("*.py"))
    for path in md:
        text = path.read_text()
        assert "/tmp/" not in text, path
        assert "../shared" not in text and "SPEC.md" not in text, path


@pytest.mark.parametrize("path", [p.relative_to(ROOT) for p in tracked("config/*.yaml", "examples/*.yaml")]
                         if (ROOT / ".git").exists() else [], ids=str)
def test_config_and_example_headers_are_short(path):
    header = 0
    for line in (ROOT / path).read_text().splitlines():
        if not line.startswith("#"):
            break
        header += 1
    assert header <= MAX_HEADER


def test_at_most_twelve_maintained_benchmark_scripts():
    scripts = [p for p in tracked("benchmarks/*") if p.suffix in (".py", ".sh")]
    assert 0 < len(scripts) <= 12
