"""Help texts of the command line speak to users: plain words, an example per step, units."""

import argparse
import re

import pytest

from shadowcam.cli import STEPS, build_parser, main

#: option names asking for a length, a duration or a speed
MEASURED = re.compile(r"(width|height|distance|depth|length|time|speed|shake|size)")
#: words that give a unit (or a count, for sizes in pixels/frames)
UNIT = re.compile(r"\b(m|metres?|s|seconds?|px|pixels?|frames?|rows|cols|columns|COLSxROWS|MP|bits)\b")
#: markup or programming terms that must not reach a user
CODE_TERMS = re.compile(r"``|:func:|:mod:|add_parser|run\(args\)|subparsers")


def _step_parsers():
    parser = build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return parser, sub.choices


def test_top_help_is_for_users(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    out = capsys.readouterr().out
    description = out.split("\n\n")[1]
    assert description[0].isalpha(), description
    assert not CODE_TERMS.search(out), out
    assert "shadowcam STEP --help" in out


@pytest.mark.parametrize("step", sorted(STEPS))
def test_step_help_plain_words_example_units(step):
    _, parsers = _step_parsers()
    sub = parsers[step]
    text = sub.format_help()
    assert sub.description and sub.description[0].isupper(), sub.description
    assert not CODE_TERMS.search(text), text
    assert f"example:\n  shadowcam {step} " in text, text
    for action in sub._actions:
        if not action.option_strings or action.dest == "help":
            continue
        assert action.help, f"{step} {action.option_strings[-1]} has no help"
        if MEASURED.search(action.dest) and action.type in (int, float):
            assert UNIT.search(action.help), f"{step} {action.option_strings[-1]}: no unit in {action.help!r}"


def test_plan_errors_name_the_flags(capsys):
    code = main(["plan", "--pixel-width", "5.9e-6", "--mask-distance", "0.3", "--depth", "0.01",
                 "--focal-length", "0.035", "--frame-time", "0.04", "--image-pixels", "4000",
                 "--mask-speed", "0.002"])
    err = capsys.readouterr().err
    assert code == 2
    assert "--depth" in err and "--focal-length" in err and "focal_length" not in err, err
