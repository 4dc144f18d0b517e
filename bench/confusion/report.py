# SPDX-License-Identifier: BSD-3-Clause
"""Tables of the confusion benchmark, from the per-session records alone (so that a run's
--json file re-makes them)."""

from __future__ import annotations

from collections import Counter, defaultdict

import numpy as np

KINDS = ("right", "ambiguous", "nothing", "wrong")


def _pct(a: int, b: int) -> str:
    return f"{100.0 * a / b:.0f}%" if b else "-"


def _first(rec: dict) -> str:
    if not rec["findings"]:
        return "nothing"
    f = rec["findings"][0]
    if f["named"]:
        return f"{f['effect']} (w {f['weight']:.2f})"
    return "group[" + ", ".join(f["group"]) + f"] (best {f['effect']}, w {f['weight']:.2f})"


def cell_table(hidden: list, amps: list) -> list:
    """One row per machine, instrument, entry, noise; per amplitude right/ambiguous/nothing/wrong
    and the oracle's detection rate."""
    cells = defaultdict(list)
    for r in hidden:
        cells[(r["machine"], r["instrument"], r["entry"], r["noise"], r["amp"])].append(r)
    rows = sorted({k[:4] for k in cells})
    head = (
        "| machine | instr | entry | noise | "
        + " | ".join(f"{a:g}x r/a/n/w (oracle)" for a in amps)
        + " |"
    )
    out = [
        "### Per cell: right / right-but-ambiguous / nothing / wrong (oracle detection rate)",
        "",
        head,
        "|" + "---|" * (4 + len(amps)),
    ]
    for key in rows:
        parts = []
        for a in amps:
            rs = cells.get(key + (a,), [])
            if not rs:
                parts.append("")
                continue
            c = Counter(r["outcome"] for r in rs)
            o = sum(r["oracle"] for r in rs)
            mark = " **W**" if c["wrong"] + c["bad_group"] else ""
            parts.append(
                f"{c['right']}/{c['ambiguous']}/{c['nothing']}/{c['wrong'] + c['bad_group']}"
                f" ({_pct(o, len(rs))}){mark}"
            )
        out.append(f"| {key[0]} | {key[1]} | {key[2]} | {key[3]} | " + " | ".join(parts) + " |")
    return out


def summary_tables(hidden: list, null: list, noises: list, amps: list) -> list:
    out = [
        "### Hidden effects by noise and amplitude (all cells pooled)",
        "",
        "| noise | amp | sessions | right | ambiguous | nothing | wrong | oracle |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for nz in noises:
        for a in amps:
            rs = [r for r in hidden if r["noise"] == nz and r["amp"] == a]
            if not rs:
                continue
            c = Counter(r["outcome"] for r in rs)
            w = c["wrong"] + c["bad_group"]
            out.append(
                f"| {nz} | {a:g}x | {len(rs)} | "
                + " | ".join(_pct(c[k], len(rs)) for k in KINDS[:3])
                + f" | {_pct(w, len(rs))} | {_pct(sum(r['oracle'] for r in rs), len(rs))} |"
            )
    out += [
        "",
        "### Per noise kind",
        "",
        "| noise | wrong first cause / hidden sessions | false findings / null sessions | 2-sigma coverage (right findings) "
        "| the same by GLS under the true covariance: rotacal / GLS |",
        "|---|---|---|---|---|",
    ]
    for nz in noises:
        rs = [r for r in hidden if r["noise"] == nz]
        ns = [r for r in null if r["noise"] == nz]
        w = sum(r["outcome"] in ("wrong", "bad_group") for r in rs)
        f = sum(r["outcome"] == "false" for r in ns)
        cov = [h for r in rs for h in r.get("coverage", [])]
        both = [
            (h, g)
            for r in rs
            if "true_gls_coverage" in r
            for h, g in zip(r["coverage"], r["true_gls_coverage"])
        ]
        mine, gls = sum(h for h, _ in both), sum(g for _, g in both)
        out.append(
            f"| {nz} | {w}/{len(rs)} ({_pct(w, len(rs))}) | {f}/{len(ns)} ({_pct(f, len(ns))}) | "
            f"{sum(cov)}/{len(cov)} ({_pct(sum(cov), len(cov))}) | "
            f"{mine} / {gls} of {len(both)} ({_pct(mine, len(both))} / {_pct(gls, len(both))}) |"
        )
    out += [
        "",
        "### Diagnosis time (rotacal.diagnose: wall clock, and the CPU time of its thread)",
        "",
        "| instrument | sessions | median ms | 90th pct ms | median CPU ms | 90th pct CPU ms |",
        "|---|---|---|---|---|---|",
    ]
    for inst in sorted({r["instrument"] for r in hidden + null}):
        rows = [r for r in hidden + null if r["instrument"] == inst]
        t = np.array([r["time_ms"] for r in rows])
        c = np.array([r.get("cpu_ms", np.nan) for r in rows])
        out.append(
            f"| {inst} | {len(t)} | {np.median(t):.0f} | {np.percentile(t, 90):.0f} | "
            f"{np.median(c):.0f} | {np.percentile(c, 90):.0f} |"
        )
    return out


def wrong_list(hidden: list, null: list) -> list:
    """Every cell where rotacal names a wrong cause, with what it named; then false findings."""
    groups = defaultdict(list)
    for r in hidden:
        if r["outcome"] in ("wrong", "bad_group"):
            groups[(r["entry"], r["instrument"], r["machine"], r["noise"], r["amp"])].append(r)
    out = [
        "### Wrong first causes (entry, instrument, machine, noise, amplitude: what was named)",
        "",
    ]
    if not groups:
        out.append("none")
    for key in sorted(groups):
        named = Counter(_first(r) for r in groups[key])
        n_cell = sum(
            1
            for r in hidden
            if (r["entry"], r["instrument"], r["machine"], r["noise"], r["amp"]) == key
        )
        out.append(
            f"- {key[0]} | {key[1]} | {key[2]} | {key[3]} | {key[4]:g}x: {len(groups[key])}/{n_cell}: "
            + "; ".join(f"{k}" + (f" x{v}" if v > 1 else "") for k, v in named.most_common())
        )
    out += ["", "### False findings on null sessions", ""]
    falses = [r for r in null if r["outcome"] == "false"]
    if not falses:
        out.append("none")
    for r in falses:
        out.append(
            f"- {r['instrument']} | {r['machine']} | {r['noise']} | draw {r['draw']}: {_first(r)}"
        )
    return out


def skipped_table(entries: list) -> list:
    out = ["### Entries without a cell (no half-detection amplitude at a plausible size)", ""]
    by = defaultdict(list)
    for e in entries:
        if e.get("a_half") is None:
            by[(e["machine"], e["instrument"])].append(f"{e['entry']} ({e['why']})")
    if not by:
        out.append("none")
    for k in sorted(by):
        out.append(f"- {k[0]} {k[1]}: " + "; ".join(by[k]))
    return out


def amplitude_table(entries: list) -> list:
    out = [
        "### Half-detection amplitudes (refsim units; thermal_warmup: d, tau fixed)",
        "",
        "| machine | instr | entry | a_half | unit | visible fraction |",
        "|---|---|---|---|---|---|",
    ]
    for e in sorted(entries, key=lambda e: (e["machine"], e["instrument"], e["entry"])):
        if e.get("a_half") is not None:
            out.append(
                f"| {e['machine']} | {e['instrument']} | {e['entry']} | {e['a_half']:.3g} | {e['unit']} | "
                f"{e['visible_fraction']:.2f} |"
            )
    return out


def tables(doc: dict, per_cell: bool = True) -> str:
    cfg = doc["config"]
    recs = doc["records"]
    hidden = [r for r in recs if r["entry"] is not None]
    null = [r for r in recs if r["entry"] is None]
    amps = sorted({r["amp"] for r in hidden}) or cfg["amplitudes"]
    parts = [
        f"## rotacal diagnosis confusion benchmark (refsim data; seed {cfg['seed']}, {cfg['draws']} draws per cell, "
        f"{cfg['null']} null sessions per noise kind)",
        "",
        "Motion-only entries skipped (refsim models static poses only): "
        + (", ".join(doc.get("motion_only", [])) or "none"),
        "",
    ]
    parts += summary_tables(hidden, null, cfg["noise"], amps) + [""]
    parts += wrong_list(hidden, null) + [""]
    if per_cell:
        parts += cell_table(hidden, amps) + [""]
    parts += skipped_table(doc["entries"])
    return "\n".join(parts)
