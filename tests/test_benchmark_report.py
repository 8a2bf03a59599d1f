"""The benchmark report (benchmarks/README.md): short, with its figures present, about the project only."""
import re
from pathlib import Path

BENCH = Path(__file__).resolve().parents[1] / "benchmarks"


def _readme() -> str:
    return (BENCH / "README.md").read_text(encoding="utf-8")


def test_report_is_at_most_500_lines():
    assert len(_readme().splitlines()) <= 500


def test_report_links_at_least_four_figures_that_exist():
    links = re.findall(r"!\[[^\]]*\]\((figures/[^)]+\.png)\)", _readme())
    assert len(set(links)) >= 4
    missing = [link for link in links if not (BENCH / link).is_file()]
    assert not missing, missing


def test_report_speaks_of_the_project_only():
    words = re.findall(r"\bsessions?\b|\bissues? \d+", _readme(), flags=re.IGNORECASE)
    assert not words, words
