# SPDX-License-Identifier: BSD-3-Clause
"""The HTML report, opened in headless Chromium as a person would open it."""

import re
import shutil
import subprocess

import pytest

from conftest import run_cli

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def write_report(session, out):
    r = run_cli("report", session, "-o", out)
    assert r.returncode == 0, r.stderr
    return out


@pytest.fixture(scope="module")
def report(shared_data, tmp_path_factory):
    return write_report(
        shared_data / "ballbar_ac_table2.csv", tmp_path_factory.mktemp("report") / "report.html"
    )


def test_report_is_self_contained(report):
    html = report.read_text()
    assert not re.search(r"(src|href)=\"(https?:)?//", html), "the report must open without network"
    assert html.count("data:image/png;base64,") >= 5


@pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is installed by scripts/setup.sh")
def test_report_renders_in_chromium(report, tmp_path):
    profile = tmp_path / "profile"
    dom = subprocess.run(
        [CHROMIUM, *FLAGS, f"--user-data-dir={profile}", "--dump-dom", report.as_uri()],
        capture_output=True,
        text=True,
        timeout=120,
    ).stdout
    for section in ("setup", "location-errors", "polar", "residuals", "diagnosis"):
        assert f'id="{section}"' in dom, section
    n = int(re.search(r'data-images="(\d+)"', dom).group(1))
    ok = int(re.search(r'data-images-rendered="(\d+)"', dom).group(1))
    assert n >= 5 and ok == n, (ok, n)
    png = tmp_path / "shot.png"
    subprocess.run(
        [
            CHROMIUM,
            *FLAGS,
            f"--user-data-dir={profile}",
            "--window-size=1200,2400",
            f"--screenshot={png}",
            report.as_uri(),
        ],
        capture_output=True,
        timeout=120,
    )
    assert png.stat().st_size > 50_000  # a page with tables and plots, not a blank one


@pytest.fixture(scope="module")
def rtest_report(shared_data, tmp_path_factory):
    return write_report(
        shared_data / "rtest_bc_oyama.csv", tmp_path_factory.mktemp("rtest_report") / "report.html"
    )


def test_rtest_report_is_self_contained(rtest_report):
    html = rtest_report.read_text()
    assert not re.search(r"(src|href)=\"(https?:)?//", html), "the report must open without network"
    for name in ("E_X0B", "E_Z0B", "E_A0B", "E_C0B", "E_X0C", "E_Y0C", "E_A0C", "E_B0C"):
        assert f"<td class=l>{name}</td>" in html, name  # the location-error table
    assert "data:text/csv;base64," in html  # the map at the measured angles, downloadable offline


@pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is installed by scripts/setup.sh")
def test_rtest_report_renders_in_chromium(rtest_report, tmp_path):
    profile = tmp_path / "profile"
    dom = subprocess.run(
        [CHROMIUM, *FLAGS, f"--user-data-dir={profile}", "--dump-dom", rtest_report.as_uri()],
        capture_output=True,
        text=True,
        timeout=120,
    ).stdout
    for section in ("setup", "location-errors", "error-map", "residuals", "diagnosis"):
        assert f'id="{section}"' in dom, section
    # The two error-map figures (w_BY against B, w_CB against C) are there and decode.
    assert dom.count('data-section="error-map"') == 2
    n = int(re.search(r'data-images="(\d+)"', dom).group(1))
    ok = int(re.search(r'data-images-rendered="(\d+)"', dom).group(1))
    assert n >= 3 and ok == n, (ok, n)
    png = tmp_path / "shot.png"
    subprocess.run(
        [
            CHROMIUM,
            *FLAGS,
            f"--user-data-dir={profile}",
            "--window-size=1200,2400",
            f"--screenshot={png}",
            rtest_report.as_uri(),
        ],
        capture_output=True,
        timeout=120,
    )
    assert png.stat().st_size > 50_000


def walk_session(shared_data, path):
    """The shared R-test session with AR(1) noise (rho 0.9, 0.3 um) and probe zeros that wander
    0.1 um per pose added to each channel: the joint fit refits under REML AR(1) + walk."""
    import numpy as np
    import rotacal
    from rotacal import _core

    s = rotacal.load(shared_data / "rtest_bc_oyama.csv")
    setups, t = list(s.setups), list(s.time)
    e = np.zeros((len(t), 3))
    for k in range(3):
        g = [f"{u}:{k}" for u in setups]
        e[:, k] = np.asarray(_core.noise_ar1(g, t, 0.9, 0.3e-3, 10 + k)) + np.asarray(
            _core.noise_probe_zero_wander(g, t, 0.1e-3, 20 + k)
        )
    rotacal.save(s.with_displacements(np.asarray(s.d) + e), path)
    return path


def test_rtest_report_says_reml_walk_not_a_factor(shared_data, tmp_path):
    """The R-test's covariance is REML AR(1) + walk per stream, not a factor for what the fit
    absorbs: the report says so and shows each stream's walk step."""
    html = write_report(
        walk_session(shared_data, tmp_path / "walk.csv"), tmp_path / "w.html"
    ).read_text()
    section = html[html.index('id="uncertainty"') :]
    assert "AR(1) + random walk per stream, estimated by REML" in section
    assert "for the correlation the fit absorbs" not in html
    steps = re.findall(
        r"<td>(\d+\.\d{4})</td><td>[\d.]+</td><td>[\d.e+-]+</td><td>\d+</td></tr>", section
    )
    assert len(steps) == 6 and all(0.03 < float(v) < 0.4 for v in steps), steps


def test_ballbar_report_keeps_the_bias_factor_words(shared_data, tmp_path):
    """The ballbar's Burg model is scaled by its bootstrap factor: that stays in the words."""
    import numpy as np
    import rotacal
    from rotacal import _core

    s = rotacal.load(shared_data / "ballbar_ac_table2.csv")
    e = _core.noise_ar1(list(s.tests), list(s.time), 0.9, 0.5e-3, 3)
    rotacal.save(s.with_lengths(np.asarray(s.length) + e), tmp_path / "ar.csv")
    html = write_report(tmp_path / "ar.csv", tmp_path / "ar.html").read_text()
    assert re.search(
        r"1-sigma by GLS under it, covariance x \d\.\d\d for the correlation the fit absorbs", html
    )
    assert "random-walk step" not in html
