"""The option table walked through both front ends: every option of run, capture and compare
(`seethru.options()`), at each end of its range, one beyond and with a wrong type, is taken or
refused alike by the command line (`seethru spec COMMAND --flag value`) and by Python
(`seethru.spec(command, keyword=value)`), with the same range in the error; and
`seethru.run` measures what `seethru run` writes for every option combination of the smoke
matrix (../shared/tools/smoke_matrix.sh) on every bundled scene."""

import json
import math

import pytest

import seethru
from conftest import REPO, seethru_cli
from test_run_options import keyword_names

OPTIONS = seethru.options()
COMMANDS = ["run", "capture", "compare", "sequence", "render"]


def text(value) -> str:
    """A Python value as the command line writes it."""
    if isinstance(value, (list, tuple)):
        return ",".join(text(v) for v in value)
    if isinstance(value, float) and math.isinf(value):
        return "inf"
    return str(value)


def cli_args(option: dict, value) -> list[str]:
    if option["kind"] == "switch":
        return [option["flag"]] if value else []
    return [f"{option['flag']}={text(value)}"]


def cases(option: dict):
    """(value, taken) at each end of the range, one beyond, and of a wrong type; taken None:
    either, by a rule of the command (a capture is of one eye), but alike."""
    kind, low, high = option["kind"], option["min"], option["max"]
    if kind == "integer":
        low, high = int(low), int(high)
        yield low, True
        yield high, True
        yield low - 1, False
        yield high + 1, False
    elif kind in ("number", "distance"):
        yield low, True
        yield high, True
        # One beyond the low end: half of it above 0, one below it otherwise.
        yield (low / 2 if low > 0 else low - 1.0), False
        yield high * 1.5 + 1, False
        if kind == "distance":
            yield "inf", True
            yield "auto", True
    elif kind == "triple":
        yield [high] * 3, True
        yield [low] * 3, True
        yield [high * 1.01, 0.0, 0.0], False
        yield [low * 1.01, 0.0, 0.0], False
    elif kind == "choice":
        for name in option["choices"]:
            yield name, None
        yield "no-such-choice", False
    elif kind == "switch":
        yield True, True
        yield False, True
    if kind != "switch":
        yield "abc", False


def context(option: dict, command: str) -> dict:
    """The settings under which `command` reads `option`, as the table names them."""
    names = {o["name"]: o for o in OPTIONS if command in o["commands"]}
    out = {}
    for name, value in option["read_with"].items():
        if name in names:
            out[name] = {"true": True, "false": False}.get(value, value)
            if names[name]["kind"] == "number":
                out[name] = float(value)
    return out


WALK = [(c, o, v, taken) for c in COMMANDS for o in OPTIONS if c in o["commands"] for v, taken in cases(o)]


@pytest.mark.parametrize(
    "command,option,value,taken", WALK, ids=[f"{c}-{o['name']}-{v!r}" for c, o, v, _ in WALK]
)
def test_each_option_is_taken_or_refused_alike_by_both_front_ends(command, option, value, taken):
    given = {**context(option, command), option["name"]: value}
    by_name = {o["name"]: o for o in OPTIONS}
    flags = [a for name, v in given.items() for a in cli_args(by_name[name], v)]
    cli = seethru_cli("spec", command, *flags)
    try:
        python, python_error = seethru.spec(command, **given), None
    except ValueError as e:
        python, python_error = None, str(e)
    assert (cli.returncode == 0) == (python_error is None), (flags, cli.stderr, python_error)
    if taken is not None:
        assert (cli.returncode == 0) == taken, (flags, cli.stderr)
    if cli.returncode == 0:
        assert json.loads(cli.stdout) == python
        shown = python["options"][option["name"]]
        if option["kind"] not in ("switch", "choice", "distance", "triple"):
            assert shown == pytest.approx(value)
        return
    said = cli.stderr.strip()
    assert said.startswith("error:") and "\n" not in said, said
    if taken is None:
        # Refused by a rule: the same reason after the option.
        assert said.split(": ", 2)[2] == python_error.split(": ", 1)[1], (said, python_error)
    elif option["kind"] == "choice":
        for name in option["choices"]:
            assert name in said and name in python_error, (said, python_error)
    else:
        need = "must be "
        cli_need = said[said.index(need):]
        assert cli_need in python_error, (said, python_error)
        assert option["flag"] in said and option["name"] in python_error


def test_the_walk_covers_every_option_of_every_command():
    walked = {(c, o["name"]) for c, o, _, _ in WALK}
    assert walked == {(c, o["name"]) for c in COMMANDS for o in OPTIONS if c in o["commands"]}
    assert len(OPTIONS) >= 29


def test_python_refuses_what_the_command_line_has_no_value_for():
    # A switch is a bool in Python: a string is refused, not read as true.
    with pytest.raises(ValueError, match=r"require_confident_head='yes': must be true or false"):
        seethru.spec("run", require_confident_head="yes")
    # A bool is not a number.
    with pytest.raises(ValueError, match=r"width=True: must be an integer in \[1, 16384\]"):
        seethru.spec("run", width=True)
    with pytest.raises(ValueError, match=r'unknown option "fill": the options are head, head_bias_cm'):
        seethru.spec("capture", fill="inpaint")


# The smoke matrix's options of `run` that Python has (`--eyes both` writes two runs; `--exr`
# only shapes the files).
SMOKE = [
    {},
    {"head": "estimated"},
    {"head": "model"},
    {"method": "ground"},
    {"method": "plane-fit"},
    {"method": "depth"},
    {"display": "ideal"},
    {"d2": "auto"},
    {"d2": "inf"},
    {"outside": "black"},
]
SCENES = sorted((REPO / "scenes").glob("*.toml"))


@pytest.mark.parametrize("scene_path", SCENES, ids=[s.stem for s in SCENES])
def test_run_measures_what_the_command_line_writes_for_the_smoke_matrix(tmp_path, scene_path):
    scene = seethru.Scene.load(scene_path)
    for i, keywords in enumerate(SMOKE):
        by_name = {o["name"]: o for o in OPTIONS}
        flags = [a for name, v in keywords.items() for a in cli_args(by_name[name], v)]
        out = tmp_path / str(i)
        cli = seethru_cli("run", str(scene_path), "--width", "48", "--spp", "1", "--out", str(out), *flags)
        try:
            run, error = seethru.run(scene, width=48, spp=1, **keywords), None
        except ValueError as e:
            run, error = None, str(e)
        if cli.returncode != 0:
            said = cli.stderr.strip().removeprefix("error: ")
            assert error is not None, (keywords, said)
            assert keyword_names(said) == error, (said, error)
            continue
        assert error is None, (keywords, error)
        assert run.metrics == json.loads((out / "metrics.json").read_text()), keywords
        assert run.hazards == json.loads((out / "hazards.json").read_text()), keywords


def sequence_keywords() -> set[str]:
    """The keywords of `seethru.sequence`: the flags of `seethru sequence --help`."""
    import re

    help_text = seethru_cli("sequence", "--help").stdout
    return {f.replace("-", "_") for f in re.findall(r"--([a-z0-9-]+)", help_text)}


# The options a sequence shares with a run: the table's, but `head` (a sequence's `head` is
# the head's motion; its source is `head_source`) and `latency_camera` (a run's is one
# instant's latency; a sequence takes a list of them, one sequence each, with its own parser
# over the table's range, MAX_LATENCY_MS).
NOT_SHARED = {"head", "latency_camera"}
SHARED = [o for o in OPTIONS if o["name"] in sequence_keywords() and o["name"] not in NOT_SHARED]
REFUSED = [(o, v) for o in SHARED for v, taken in cases(o) if taken is False]


@pytest.mark.parametrize("option,value", REFUSED, ids=[f"{o['name']}-{v!r}" for o, v in REFUSED])
def test_sequence_refuses_a_shared_option_in_the_words_of_run(option, value):
    # One parser per option: a sequence reads what it shares with a run through the table, so
    # a bad value is refused with the same words (and range) as by `seethru.run`.
    scene = seethru.Scene.load(REPO / "scenes" / "das.toml")
    with pytest.raises(ValueError) as by_sequence:
        seethru.sequence(scene, **{option["name"]: value})
    with pytest.raises(ValueError) as by_run:
        seethru.spec("sequence", **{option["name"]: value})
    assert str(by_sequence.value) == str(by_run.value)


def test_a_sequence_shares_most_of_a_runs_options():
    assert len(SHARED) >= 17, [o["name"] for o in SHARED]
