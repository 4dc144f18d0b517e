# SPDX-License-Identifier: BSD-3-Clause
"""The report's compensation section (`rotacal report --controller NAME`, issue 54 item 4): for
the chosen controller, what its kinematics and its tables correct, and what remains for
`rotacal compensate`, with each term's size over the travel. The model with known error
motions is written out from effects.md (test_comp_tables.model_doc), not taken from rotacal."""

import json
import re

from conftest import run_cli
from test_comp_tables import model_doc

from rotacal.report.controller import controller_section


def rows(html):
    return {
        m[1]: (m[2], m[3])
        for m in re.finditer(
            r"<tr><td class=l>([^<]+)</td><td>([^<]+)</td><td class=l>([^<]+)</td>", html
        )
    }


def test_the_section_says_which_terms_the_tables_hold_and_what_remains():
    html = controller_section(model_doc(), "linuxcnc")
    r = rows(html)
    assert r["positioning_C"][1] == "table comp_C.txt"
    # The C run-out of 2 um (radial_motion_C_h2, a = 2e-3 mm) and the sag stay for compensate.
    assert r["E_XC"] == ("2.00 &micro;m", "left to rotacal compensate")
    assert r["E_ZA"][1] == "left to rotacal compensate"
    assert "E_CC" not in r  # C's rotation about Z is its positioning: one row, held
    assert r["E_X0C"][1].startswith("kinematics: x-rot-point")
    assert r["E_A0C"][1] == "left to rotacal compensate"  # no orientation pins in trt kins
    remains = html.split("Remains after loading:")[1]
    assert "E_XC 2.00" in remains and "positioning_C" not in remains
    # SINUMERIK holds the tilts in its kinematics, the positioning in an EEC table and the
    # translations (run-out, sag) in CEC tables.
    r = rows(controller_section(model_doc(), "siemens"))
    assert r["positioning_C"][1] == "table eec_C.mpf" and r["E_A0C"][1].startswith("kinematics")
    assert r["E_XC"][1] == "table cec_C.mpf" and r["E_ZA"][1] == "table cec_A.mpf"
    # ... the C tables at A = 0 only: away from it the run-out turns with A (up to 2 um x 2).
    away = r["E_XC, E_YC, E_ZC away from A = 0"]
    assert away[1] == "left to rotacal compensate" and 2.0 < float(away[0].split()[0]) <= 4.0
    # ISG: the positioning in kw.ssfk, each slave's translation in kw.crosscomp.
    r = rows(controller_section(model_doc(), "isg"))
    assert r["positioning_C"][1] == "table ssfk_C.lis" and r["E_XC"][1] == "table crosscomp_X.lis"


def test_report_of_a_session_adds_the_section_as_the_export_holds_it(shared_data, tmp_path):
    session = shared_data / "ballbar_ac_table2.csv"
    out = tmp_path / "r.html"
    r = run_cli("report", session, "--controller", "linuxcnc", "--no-diagnosis", "-o", out)
    assert r.returncode == 0, r.stderr
    section = out.read_text().split('<section id="controller">')[1].split("</section>")[0]
    m = tmp_path / "m.json"
    assert run_cli("identify", session, "--no-budget", "--save-model", m).returncode == 0
    j = json.loads(run_cli("export", "--model", m, "--controller", "linuxcnc", "--json").stdout)
    got = rows(section)
    for e in j["location_errors"]:
        held = got[e["name"]][1]
        assert held.startswith("kinematics") == e["held"], (e["name"], held)
        scale = 1e3 if e["name"][2] in "XYZ" else 1e6
        assert got[e["name"]][0].split()[0] == f"{abs(e['value']) * scale:.2f}"
    r = run_cli("report", session, session, "--controller", "linuxcnc", "-o", out)
    assert r.returncode == 3 and "--controller" in r.stderr
