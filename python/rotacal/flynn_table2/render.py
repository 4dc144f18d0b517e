# SPDX-License-Identifier: BSD-3-Clause
"""The analysis in words: its conclusions, and a plain-text rendering of the result."""

from __future__ import annotations


def conclusions(r: dict) -> list[str]:
    out = []
    n_out = len(r["outside"])
    out.append(
        f"{n_out} of 8 measured post-compensation values fall outside the simulated interval (mean +- 2 std)"
        + (f": {', '.join(r['outside'])}." if n_out else ".")
    )
    cmax = max(r["constant_effects_largest_after_value"].items(), key=lambda t: t[1])
    out.append(
        "Effects that stay the same in both runs cancel in the chain: the largest post-compensation value "
        f"any of them produces at its plausible size is {cmax[1]:.2f} {r['prediction'][cmax[0]]['unit']} "
        f"({cmax[0]})."
    )
    for n, v in r["per_value"].items():
        if v["verdict"] != "within the predicted spread":
            out.append(
                f"{n}: deviation {v['deviation']:+.2f} {v['unit']}: {v['verdict']}"
                + (
                    f" (largest change between runs at a plausible size: {v['between_runs']['largest_at_plausible_size']:.2f}"
                    f" {v['unit']}, {v['between_runs']['by']})"
                    if v["verdict"] == "no single cause at a plausible size"
                    else ""
                )
                + "."
            )
    for g in r["ambiguous"]:
        out.append(
            f"Not told apart by the 8 values: {', '.join(g['candidates'])}; "
            + (
                f"run 2's raw {g['separating_test']} data would separate them."
                if g["raw_data_separates"]
                else "no test of the session separates them; "
                + "; ".join(g["further_measurement"])
                + "."
            )
        )
    if any(c["kind"] == "between_runs" for c in r["ranked_causes"][:1]):
        out.append(
            "A repeated uncompensated run after the same interval tells every change between the runs "
            "from a constant effect: a change moves its before-values by the size it adds after compensation "
            "(ranked_causes[].repeat_uncompensated_shift), a constant effect does not move them."
        )
    e = r["extended_model"]
    for u, t in e["sum_abs_unexplained"].items():
        out.append(
            f"Extended model ({len(e['causes'])} causes at plausible sizes) accounts for {t['accounted_for']:.2f} "
            f"of {t['baseline']:.2f} {u} (sum of |measured - predicted| over the {u} values); "
            f"{t['extended']:.2f} {u} remain."
        )
    if not r["sweep"]:
        return out
    stable = [s["scenario"] for s in r["sweep"] if set(s["outside"]) == set(r["outside"])]
    out.append(
        f"The same values fall outside in {len(stable)} of {len(r['sweep'])} swept scenarios"
        + (
            f" (differs in: {', '.join(s['scenario'] for s in r['sweep'] if s['scenario'] not in stable)})."
            if len(stable) < len(r["sweep"])
            else "."
        )
    )
    return out


def render(r: dict) -> str:
    """Plain-text rendering of analyse()'s result."""
    L = []
    a = r["assumptions"]
    L.append(
        "Flynn et al. (2016) Table 2: measured before/after compensation vs the simulated chain"
    )
    L.append(
        f"assumed: bar {a['ballbar_length']:g} mm, pivot {a['pivot']}, A {a['tilt_range_deg']}, "
        f"C {a['rot_range_deg']}, step {a['step_deg']:g} deg, noise {a['noise_um']:g} um AR(1) {a['noise_rho']:g}, "
        f"{a['hours_between_runs']:g} h between runs (tau {a['thermal_time_constant_h']:g} h), "
        f"method {a['method']}, {a['draws']} draws"
    )
    L.append("")
    L.append(
        "error   unit   before   measured after   predicted (mean +- std)   interval (k=2)       z   outside"
    )
    for n, p in r["prediction"].items():
        L.append(
            f"{n:6s} {p['unit']:5s} {p['before']:+9.2f} {p['measured_after']:+12.2f}   "
            f"{p['predicted_mean']:+9.2f} +- {p['predicted_std']:6.2f}     "
            f"[{p['interval_k2'][0]:+7.2f}, {p['interval_k2'][1]:+7.2f}] {p['z']:+8.1f}   {'yes' if p['outside'] else 'no'}"
        )
    L.append("")
    L.append("which kind of cause can produce each value alone, at a plausible size:")
    for n, v in r["per_value"].items():
        L.append(
            f"  {n}: {v['verdict']}; constant effects reach {v['constant']['largest_at_plausible_size']:.2f} {v['unit']}, "
            f"changes between runs {v['between_runs']['largest_at_plausible_size']:.2f} {v['unit']} "
            f"({v['between_runs']['by']})"
        )
    L.append("")
    L.append(
        "causes ranked (one at a time; size fitted to the 8 deviations, checked against its plausible size):"
    )
    for i, c in enumerate(r["ranked_causes"], 1):
        sd = f" +- {c['size_std']:.2f}" if c["size_std"] is not None else ""
        L.append(
            f"  {i:2d}. {c['id']:40s} {c['size']:+9.2f}{sd} {c['unit']} (plausible {c['plausible']:.2f}, "
            f"x{c['size_over_plausible']:.1f}{'' if c['plausible_size'] else ' TOO LARGE'}) chi2 {c['chi2']:.0f}"
        )
    if r["ambiguous"]:
        L.append("")
        L.append("causes these 8 values cannot tell apart:")
        for g in r["ambiguous"]:
            how = (
                f"raw data of test {g['separating_test']} separates them ({g['rms_difference_um']:.2f} um RMS)"
                if g["raw_data_separates"]
                else "no test of the session separates them"
            )
            L.append(
                f"  {', '.join(g['candidates'])}: {how}; " + "; ".join(g["further_measurement"])
            )
    e = r["extended_model"]
    L.append("")
    L.append("extended model (causes at plausible sizes, greedy):")
    for c in e["causes"]:
        L.append(f"  {c['id']:40s} {c['size']:+9.2f} {c['unit']} (plausible {c['plausible']:.2f})")
    L.append("error   unit   measured   baseline   extended   unexplained before -> after")
    for n, g in e["per_value"].items():
        L.append(
            f"{n:6s} {g['unit']:5s} {g['measured']:+9.2f} {g['baseline']:+9.2f} {g['extended']:+9.2f}   "
            f"{g['unexplained_before']:+9.2f} -> {g['unexplained_after']:+9.2f}"
        )
    L.append("")
    L.append("sweep of the assumptions:")
    for s in r["sweep"]:
        t = s["top_causes"][0]
        L.append(
            f"  {s['scenario']:24s} outside: {','.join(s['outside']) or '-':48s} first cause {t['id']} "
            f"{t['size']:+.2f} {t['unit']}; unexplained um {s['sum_abs_unexplained']['um']['baseline']:.1f}"
            f"->{s['sum_abs_unexplained']['um']['extended']:.1f}, urad "
            f"{s['sum_abs_unexplained']['urad']['baseline']:.1f}->{s['sum_abs_unexplained']['urad']['extended']:.1f}"
        )
    L.append("")
    L += [f"- {c}" for c in r["conclusions"]]
    return "\n".join(L)
