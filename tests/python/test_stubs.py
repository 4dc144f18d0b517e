# SPDX-License-Identifier: BSD-3-Clause
"""The committed _core.pyi is what pybind11-stubgen (pinned) makes of the built extension."""

import rotacal._stubgen as stubgen


def test_stubs_match_the_extension():
    text = stubgen.generate()
    committed = stubgen.STUB.read_text()
    assert committed == text, (
        "python/rotacal/_core.pyi is stale: run python -m rotacal._stubgen and commit it"
    )


def test_stub_check_fails_on_a_changed_binding(tmp_path, monkeypatch):
    # The check must fail when the stub lacks a binding: drop one function from a copy.
    text = stubgen.STUB.read_text()
    assert "def read_session(" in text
    stale = tmp_path / "_core.pyi"
    stale.write_text(text.replace("def read_session(", "def read_session_renamed("))
    monkeypatch.setattr(stubgen, "STUB", stale)
    assert stubgen.main(["--check"]) == 1
