"""The fast set starts nothing: the guard of :mod:`tests.support.slow_guard`, and the marks on the tests."""

from __future__ import annotations

import sys

import pytest

from tests.conftest import GUARD, REPO
from tests.support.slow_guard import EVENTS, SlowGuard


@pytest.mark.parametrize(
    ("event", "args", "expected"),
    [
        pytest.param(
            "subprocess.Popen",
            ("git", ["git", "ls-files"], None, None),
            "starts a process (subprocess.Popen ['git', 'ls-files'])",
            id="a-process",
        ),
        pytest.param(
            "socket.bind",
            (object(), ("127.0.0.1", 1883)),
            "binds a socket (a broker, or a port for one) (socket.bind (('127.0.0.1', 1883),))",
            id="a-broker",
        ),
        pytest.param("os.fork", (), "forks its process (os.fork ())", id="a-fork"),
        pytest.param("open", ("file", "r", 0), None, id="a-file-is-fine"),
    ],
)
def test_the_guard_notes_what_a_fast_test_may_not_start(event, args, expected):
    guard = SlowGuard()
    guard.watch(True)
    guard.audit(event, args)
    assert guard.take() == expected
    assert guard.take() is None  # forgotten once taken


def test_the_guard_keeps_the_first_event_and_ignores_slow_tests():
    guard = SlowGuard()
    guard.watch(False)
    guard.audit("subprocess.Popen", ("a", ["a"], None, None))
    assert guard.take() is None
    guard.watch(True)
    guard.audit("socket.bind", (None, ("::1", 0)))
    guard.audit("subprocess.Popen", ("b", ["b"], None, None))
    assert guard.take().startswith("binds a socket")
    guard.watch(True)  # a new test begins with nothing found
    assert guard.take() is None


def test_the_guard_is_installed_for_this_fast_test():
    sys.audit("subprocess.Popen", "sphinx", ["python", "-m", "sphinx"], None, None)
    found = GUARD.take()  # taken here, so that this test passes
    assert found == "starts a process (subprocess.Popen ['python', '-m', 'sphinx'])"


def test_slow_marks_sit_on_the_tests_not_in_lists():
    conftest = (REPO / "tests" / "conftest.py").read_text(encoding="utf-8")
    for name in ("SLOW_FILES", "SLOW_TESTS", "SLOW_LEGS", "add_marker"):
        assert name not in conftest
    assert set(EVENTS) >= {"subprocess.Popen", "socket.bind", "os.posix_spawn", "os.fork"}


def test_a_thread_older_than_the_test_is_not_held_against_it():
    import threading

    guard = SlowGuard()
    started, release = threading.Event(), threading.Event()

    def left_over():  # a thread an earlier test left running
        started.set()
        release.wait(5)
        guard.audit("subprocess.Popen", ("x", ["x"], None, None))

    thread = threading.Thread(target=left_over)
    thread.start()
    started.wait(5)
    guard.watch(True)  # this test begins after the thread
    release.set()
    thread.join(5)
    assert guard.take() is None
    guard.audit("subprocess.Popen", ("y", ["y"], None, None))  # the test's own thread is watched
    assert guard.take() == "starts a process (subprocess.Popen ['y'])"
