# SPDX-License-Identifier: BSD-3-Clause
"""BENCHMARKS.md is what bench/report.py makes of the benchmarks' kept output (bench/results),
never a hand edit; and the README's table of headline figures is made from the same output."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _report():
    spec = importlib.util.spec_from_file_location("bench_report", ROOT / "bench" / "report.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_benchmarks_md_is_rendered_from_the_results():
    report = _report()
    results = report.load_results()
    assert results, "bench/results holds no benchmark output"
    assert (ROOT / "BENCHMARKS.md").read_text() == report.render(results), (
        "BENCHMARKS.md differs from `python3 bench/report.py render`: regenerate it, do not edit it"
    )


def test_readme_headline_table_is_rendered_from_the_results():
    report = _report()
    readme = (ROOT / "README.md").read_text()
    assert report.with_headlines(readme, report.load_results()) == readme, (
        "the README's headline table differs from `python3 bench/report.py render`"
    )
