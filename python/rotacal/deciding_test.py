# SPDX-License-Identifier: BSD-3-Clause
"""The loop of a ballbar diagnosis that ends in "one of these" (issue 50 item 2): the added test
that decides between two members of the group, designed after the session (design.py, the
engine of ``rotacal design ballbar --separate X,Y --after S``), and the two sessions diagnosed
together (multi_diagnosis.py). The main job (demo.py) runs it on its simulated machine."""

from __future__ import annotations

from typing import Any


def group_members(finding: dict) -> list[str]:
    """A group finding's scored members (aliased ones have no weight), highest weight first."""
    scored = [g for g in finding["group"] if not g.get("aliased")]
    return [g["effect"] for g in sorted(scored, key=lambda g: -g["weight"])]


def deciding_pairs(finding: dict) -> list[tuple[str, str]]:
    """The pairs of a group to try to separate, most useful first: the member the model holds
    against each other member by weight, then the other pairs by weight."""
    members = group_members(finding)
    held = finding["effect"] if finding["effect"] in members else members[0]
    others = [m for m in members if m != held]
    pairs = [(held, m) for m in others]
    pairs += [(a, b) for i, a in enumerate(others) for b in others[i + 1 :]]
    return pairs


def design_deciding_test(session: Any, finding: dict, base: Any) -> tuple[Any, list[dict]]:
    """The first pair of ``finding``'s group (deciding_pairs) that an added ballbar test
    separates, and its design; (None, tried) where none does. ``tried``: each pair tried with
    the design's verdict (nested pairs: no test can separate them, their table motions are the
    same; issue 50 item 3 decides those by the model rule)."""
    from .design import design_separation

    tried = []
    for pair in deciding_pairs(finding):
        d = design_separation(session, list(pair), base=base)
        tried.append(
            {
                "pair": list(pair),
                "found": bool(d.found),
                "same_motion": bool(d.motion.same_motion),
                "correlation_before": float(d.correlation_before),
                "verdict": d.verdict,
            }
        )
        if d.found:
            tried[-1]["correlation_after"] = float(d.chosen.correlation)
            return d, tried
    return None, tried
