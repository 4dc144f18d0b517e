# SPDX-License-Identifier: BSD-3-Clause
"""The JSON of the noise model, the uncertainty budget and the per-angle table follows
docs/json_schema.md: its `schema` blocks are read here and real `--json` outputs of
`rotacal identify` / `rotacal diagnose` are checked against them (a small checker; no new
dependency)."""

import json
import re
from pathlib import Path

import numpy as np
import pytest

import rotacal
from rotacal import _core

from conftest import run_cli

DOC = Path(__file__).resolve().parents[2] / "docs" / "json_schema.md"


def schemas() -> dict:
    blocks = re.findall(r"```schema (\w+)\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)
    return {name: json.loads(body) for name, body in blocks}


def check(value, schema, where: str, named: dict) -> None:
    """Raise AssertionError naming the path where `value` departs from `schema`."""
    if isinstance(schema, str):
        kinds = schema.split("|")
        if value is None:
            assert "null" in kinds, f"{where}: null where {schema} is required"
            return
        m = re.fullmatch(r"map<(\w+)>", schema)
        if m:
            assert isinstance(value, dict), f"{where}: expected an object"
            for k, v in value.items():
                check(v, named[m.group(1)], f"{where}.{k}", named)
            return
        ok = {
            "number": lambda v: (
                isinstance(v, (int, float)) and not isinstance(v, bool) and np.isfinite(v)
            ),
            "integer": lambda v: isinstance(v, int) and not isinstance(v, bool),
            "string": lambda v: isinstance(v, str),
            "boolean": lambda v: isinstance(v, bool),
        }
        assert any(ok[k](value) for k in kinds if k != "null"), (
            f"{where}: {value!r} is not {schema}"
        )
    elif isinstance(schema, list):
        assert isinstance(value, list), f"{where}: expected an array"
        for i, v in enumerate(value):
            check(v, schema[0], f"{where}[{i}]", named)
    else:
        assert isinstance(value, dict), f"{where}: expected an object"
        keys = {k.rstrip("?"): k.endswith("?") for k in schema}
        extra = set(value) - set(keys)
        assert not extra, f"{where}: keys not in the schema: {sorted(extra)}"
        for k, optional in keys.items():
            if k not in value:
                assert optional, f"{where}: missing {k!r}"
                continue
            check(value[k], schema[k + ("?" if optional else "")], f"{where}.{k}", named)


def cli_json(*args) -> dict:
    r = run_cli(*args, "--json")
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def test_document_has_the_schemas():
    assert {
        "noise_model",
        "uncertainty_budget",
        "budget_entry",
        "angle_table",
        "unexplained",
    } <= set(schemas())


def test_checker_refuses_what_departs():
    named = schemas()
    nm = {"white": True}
    with pytest.raises(AssertionError, match="missing"):
        check(nm, named["noise_model"], "noise_model", named)
    with pytest.raises(AssertionError, match="is not integer"):
        check({"n": 1.5}, {"n": "integer"}, "x", named)
    with pytest.raises(AssertionError, match="not in the schema"):
        check({"n": 1, "m": 2}, {"n": "integer"}, "x", named)


def test_identify_json_ballbar_white_and_correlated(shared_data, tmp_path):
    named = schemas()
    d = cli_json("identify", shared_data / "ballbar_ac_table2.csv")
    check(d["noise_model"], named["noise_model"], "noise_model", named)
    check(d["uncertainty_budget"], named["uncertainty_budget"], "uncertainty_budget", named)
    assert set(d["uncertainty_budget"]["location_errors"]) == set(d["location_errors"])
    # A correlated session: the noise model with its GLS refit fields.
    s = rotacal.load(shared_data / "ballbar_ac_table2.csv")
    e = _core.noise_ar1(list(s.tests), list(s.time), 0.9, 0.5e-3, 3)
    f = tmp_path / "ar.csv"
    rotacal.save(s.with_lengths(np.asarray(s.length) + e), f)
    d = cli_json("identify", f, "--no-budget")
    check(d["noise_model"], named["noise_model"], "noise_model", named)
    assert d["noise_model"]["gls_refit"] and d["noise_model"]["streams"][0]["order"] >= 1
    assert "uncertainty_budget" not in d


def test_identify_json_rtest(shared_data):
    named = schemas()
    d = cli_json("identify", shared_data / "rtest_bc_oyama.csv")
    check(d["noise_model"], named["noise_model"], "noise_model", named)
    check(d["uncertainty_budget"], named["uncertainty_budget"], "uncertainty_budget", named)


def test_diagnose_json(shared_data):
    named = schemas()
    d = cli_json("diagnose", shared_data / "ballbar_ac_table2.csv")
    assert "noise_model" in d and "angle_tables" in d and "uncertainty_budget" in d
    check(d["noise_model"], named["noise_model"], "noise_model", named)
    check(d["unexplained"], named["unexplained"], "unexplained", named)
    for i, t in enumerate(d["angle_tables"]):
        check(t, named["angle_table"], f"angle_tables[{i}]", named)
    # The shared R-test session hides a sag and a coning of B: findings to check.
    findings = cli_json("diagnose", shared_data / "rtest_bc_oyama.csv")["findings"]
    assert findings
    for i, f in enumerate(findings):
        check(f, named["finding"], f"findings[{i}]", named)
        assert 0.0 < f["weight"] <= 1.0 and f["group"][0]["effect"] == f["effect"]
        assert f["named"] == (len(f["group"]) == 1)
    check(d["uncertainty_budget"], named["uncertainty_budget"], "uncertainty_budget", named)
