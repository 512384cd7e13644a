"""A benchmark's child process: the JSON object on its last line, or one line saying why there is none."""

import pytest

from ballpit.cli.children import run_child

CHILDREN = {
    "answers": 'print("warming up")\nprint(\'{"steps": 3, "seconds": 0.5}\')\n',
    "breaks": 'print("warming up")\nraise RuntimeError("the engine blew up")\n',
    "chatters": 'print("done, but no result")\n',
    "lists": "print('[1, 2]')\n",
    "sleeps": "import time\ntime.sleep(30)\n",
    "dies": "import os\nos._exit(3)\n",
}


@pytest.fixture
def children(tmp_path, monkeypatch):
    for name, code in CHILDREN.items():
        (tmp_path / f"child_{name}.py").write_text(code)
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))  # read by the children only


@pytest.mark.parametrize(
    ("child", "expected"),
    [
        ("answers", {"steps": 3, "seconds": 0.5}),
        ("breaks", "RuntimeError: the engine blew up"),
        ("chatters", "it printed no result"),
        ("lists", "it printed no result"),
        ("dies", "exit status 3, no output"),
    ],
)
def test_a_child_gives_its_result_or_the_reason_it_has_none(children, child, expected):
    assert run_child(f"child_{child}", [], timeout=60) == expected


def test_a_child_that_takes_too_long_is_stopped_and_says_so(children):
    assert run_child("child_sleeps", [], timeout=0.5) == "no result within 0.5 s"
