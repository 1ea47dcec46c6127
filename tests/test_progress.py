"""Progress bars of long batch work: on stderr when it is a terminal, silent otherwise."""

from __future__ import annotations

import io
import sys

from trajgen.progress import progress


class Terminal(io.StringIO):
    """A stderr that says it is a terminal."""

    def isatty(self) -> bool:
        return True


def test_silent_when_stderr_is_no_terminal(monkeypatch):
    stream = io.StringIO()
    monkeypatch.setattr(sys, "stderr", stream)
    assert list(progress(range(5), description="cases")) == [0, 1, 2, 3, 4]
    assert stream.getvalue() == ""


def test_a_bar_on_stderr_when_it_is_a_terminal(monkeypatch):
    stream, stdout = Terminal(), io.StringIO()
    monkeypatch.setattr(sys, "stderr", stream)
    monkeypatch.setattr(sys, "stdout", stdout)
    assert list(progress(iter("abc"), total=3, description="cases")) == ["a", "b", "c"]
    text = stream.getvalue()
    assert "cases" in text
    assert "0/3" in text  # drawn with its total before the first item
    assert stdout.getvalue() == ""  # results on stdout stay clean


def test_without_a_total_the_bar_counts(monkeypatch):
    stream = Terminal()
    monkeypatch.setattr(sys, "stderr", stream)
    assert list(progress(iter(range(2)))) == [0, 1]
    assert "0it" in stream.getvalue()


def test_no_stderr_at_all_is_silent(monkeypatch):
    monkeypatch.setattr(sys, "stderr", None)  # pythonw and some service managers
    assert list(progress([1, 2], description="cases")) == [1, 2]
