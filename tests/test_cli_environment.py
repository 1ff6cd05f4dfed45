"""The ``gaitopt`` process's environment defaults (:data:`gaitopt.cli.PROCESS_ENVIRONMENT`)
and its progress log on stderr (:func:`gaitopt.cli.show_progress_log`)."""

from __future__ import annotations

import logging
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


def test_the_command_shows_gaitopts_progress_log_on_stderr_once(
        capfd: pytest.CaptureFixture[str]) -> None:
    """``gaitopt`` shows gaitopt's INFO records (e.g. that point libraries are being
    compiled) on stderr as plain lines, with one handler however often it is set up."""
    from gaitopt.cli import show_progress_log
    from gaitopt.ocp.pointwise import LOG

    log = logging.getLogger("gaitopt")
    before = list(log.handlers)
    try:
        for handler in before:
            log.removeHandler(handler)
        handler = show_progress_log()
        assert show_progress_log() is handler and log.handlers == [handler]
        LOG.info("compiling %d point libraries", 3)
        assert capfd.readouterr().err == "compiling 3 point libraries\n"
    finally:
        for handler in list(log.handlers):
            log.removeHandler(handler)
        for handler in before:
            log.addHandler(handler)
