"""Every ```python block of the README and docs/, run as a reader would run it.

Each page runs in a scratch folder of its own holding copies of scenes/ and assets/: first the
page's documented `seethru` command lines (its ```sh blocks, in order: the Python blocks read
what they write, as py_check/truth.exr or inputs/), then its Python blocks in order, in one
namespace, so a block may use the names an earlier block made. A line whose comment says it
raises (`# ValueError: …`) must raise that error. tests/readme.rs checks the commands
themselves; this checks that the Python a reader copies works (the Python guide's quick start
raised KeyError on a key that had moved).
"""

import os
import pathlib
import re
import shlex
import shutil
import subprocess

import pytest

from conftest import REPO

BIN = os.environ.get("SEETHRU_BIN", "seethru")
FENCE = re.compile(r"^```(\w*)\s*$")
RAISES = re.compile(r"#\s*(ValueError|OSError|KeyError|RuntimeError)\b")


def pages():
    return sorted([REPO / "README.md", *REPO.glob("docs/**/*.md")])


def blocks(path, language):
    """(first line number, text) of each fenced block of `language` in the page."""
    found, inside = [], None  # inside: (language, first line, lines) of the open block
    for number, line in enumerate(path.read_text().splitlines(), 1):
        fence = FENCE.match(line)
        if inside is None:
            if fence:
                inside = (fence.group(1), number + 1, [])
        elif line.strip() == "```":
            if inside[0] == language:
                found.append((inside[1], "\n".join(inside[2])))
            inside = None
        else:
            inside[2].append(line)
    return found


def seethru_commands(path):
    """The `seethru …` lines of the page's ```sh blocks, continuation lines joined."""
    commands = []
    for _, text in blocks(path, "sh"):
        for line in text.replace("\\\n", " ").splitlines():
            line = line.strip()
            if line.startswith("seethru "):
                commands.append(shlex.split(line)[1:])
    return commands


def runnable(text):
    """The block with each line that documents an exception wrapped to expect it."""
    out = []
    for line in text.splitlines():
        raises = RAISES.search(line)
        if raises and not line.startswith((" ", "\t")):
            code = line[: raises.start()].rstrip()
            out.append(f"with __pytest.raises({raises.group(1)}):\n    {code}")
        else:
            out.append(line)
    return "\n".join(out)


PAGES = [p for p in pages() if blocks(p, "python")]


def test_the_docs_have_python_blocks_to_run():
    # The guide's quick start is among them: a parser that found none would pass vacuously.
    names = {p.relative_to(REPO).as_posix() for p in PAGES}
    assert {"README.md", "docs/guide/python.md", "docs/guide/capture-score.md"} <= names, names
    assert len(blocks(REPO / "docs/guide/python.md", "python")) >= 3


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.relative_to(REPO).as_posix())
def test_every_python_block_of_the_page_runs(page, tmp_path, monkeypatch):
    for folder in ("scenes", "assets", "examples"):
        shutil.copytree(REPO / folder, tmp_path / folder)
    for args in seethru_commands(page):
        done = subprocess.run(
            [BIN, *args, "--quiet"], cwd=tmp_path, capture_output=True, text=True
        )
        assert done.returncode == 0, f"{page.name}: seethru {' '.join(args)}: {done.stderr}"
    monkeypatch.chdir(tmp_path)
    namespace = {"__pytest": pytest, "__name__": "__docs__"}
    for line, text in blocks(page, "python"):
        code = compile(runnable(text), f"{page.relative_to(REPO)}:{line}", "exec")
        exec(code, namespace)  # noqa: S102 — the docs' own code, which a reader runs
