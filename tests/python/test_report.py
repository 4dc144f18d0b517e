"""The HTML report, opened in headless Chromium as a person would open it."""
import re
import shutil
import subprocess
import sys

import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def write_report(session, out):
    r = subprocess.run([sys.executable, "-m", "rotacal", "report", str(session), "-o", str(out)],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return out


@pytest.fixture(scope="module")
def report(shared_data, tmp_path_factory):
    return write_report(shared_data / "ballbar_ac_table2.csv", tmp_path_factory.mktemp("report") / "report.html")


def test_report_is_self_contained(report):
    html = report.read_text()
    assert not re.search(r"(src|href)=\"(https?:)?//", html), "the report must open without network"
    assert html.count("data:image/png;base64,") >= 5


@pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is installed by scripts/setup.sh")
def test_report_renders_in_chromium(report, tmp_path):
    profile = tmp_path / "profile"
    dom = subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", "--dump-dom", report.as_uri()],
                         capture_output=True, text=True, timeout=120).stdout
    for section in ("setup", "location-errors", "polar", "residuals", "diagnosis"):
        assert f'id="{section}"' in dom, section
    n = int(re.search(r'data-images="(\d+)"', dom).group(1))
    ok = int(re.search(r'data-images-rendered="(\d+)"', dom).group(1))
    assert n >= 5 and ok == n, (ok, n)
    png = tmp_path / "shot.png"
    subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", "--window-size=1200,2400",
                    f"--screenshot={png}", report.as_uri()], capture_output=True, timeout=120)
    assert png.stat().st_size > 50_000  # a page with tables and plots, not a blank one


@pytest.fixture(scope="module")
def rtest_report(shared_data, tmp_path_factory):
    return write_report(shared_data / "rtest_bc_oyama.csv", tmp_path_factory.mktemp("rtest_report") / "report.html")


def test_rtest_report_is_self_contained(rtest_report):
    html = rtest_report.read_text()
    assert not re.search(r"(src|href)=\"(https?:)?//", html), "the report must open without network"
    for name in ("E_X0B", "E_Z0B", "E_A0B", "E_C0B", "E_X0C", "E_Y0C", "E_A0C", "E_B0C"):
        assert f"<td class=l>{name}</td>" in html, name  # the location-error table
    assert "data:text/csv;base64," in html  # the map at the measured angles, downloadable offline


@pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is installed by scripts/setup.sh")
def test_rtest_report_renders_in_chromium(rtest_report, tmp_path):
    profile = tmp_path / "profile"
    dom = subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", "--dump-dom", rtest_report.as_uri()],
                         capture_output=True, text=True, timeout=120).stdout
    for section in ("setup", "location-errors", "error-map", "residuals", "diagnosis"):
        assert f'id="{section}"' in dom, section
    # The two error-map figures (w_BY against B, w_CB against C) are there and decode.
    assert dom.count('data-section="error-map"') == 2
    n = int(re.search(r'data-images="(\d+)"', dom).group(1))
    ok = int(re.search(r'data-images-rendered="(\d+)"', dom).group(1))
    assert n >= 3 and ok == n, (ok, n)
    png = tmp_path / "shot.png"
    subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", "--window-size=1200,2400",
                    f"--screenshot={png}", rtest_report.as_uri()], capture_output=True, timeout=120)
    assert png.stat().st_size > 50_000
