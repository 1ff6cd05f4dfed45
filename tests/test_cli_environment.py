"""The ``gaitopt`` process's environment defaults (:data:`gaitopt.cli.PROCESS_ENVIRONMENT`)."""

from __future__ import annotations

import os

import pytest


def test_main_defaults_blas_to_one_thread_and_keeps_a_users_value(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """``gaitopt`` sets ``OPENBLAS_NUM_THREADS=1`` for itself and its sweep workers unless
    the environment already sets it (:data:`gaitopt.cli.PROCESS_ENVIRONMENT`)."""
    from gaitopt.cli import main

    monkeypatch.delenv("OPENBLAS_NUM_THREADS", raising=False)
    assert main(["--version"]) == 0
    assert os.environ["OPENBLAS_NUM_THREADS"] == "1"
    monkeypatch.setenv("OPENBLAS_NUM_THREADS", "4")
    assert main(["--version"]) == 0
    assert os.environ["OPENBLAS_NUM_THREADS"] == "4"
