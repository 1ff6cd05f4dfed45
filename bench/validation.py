"""Benchmark: hand-written validation against a pydantic v2 prototype (issue 26, item 5).

Measured in one run, each pydantic figure beside the hand-written one and their ratio:

* **lines**: code lines (no blank, comment or docstring lines) of the hand-written checks of
  the options (:func:`gaitopt.gait.options.gait_options.validate_options` and its helpers) and of
  the gait-file schema (``gait_fields``, ``gait_checks``, the parts' ``__post_init__``, the
  reader's checks in ``gait_file``), and of the prototype (``bench/validation_pydantic.py``:
  its validators, constrained types and message layer; the 37 field declarations, which the
  dataclass has too, are counted apart);
* **messages**: the same bad inputs through both, side by side: gaitopt's message, pydantic's
  own (first error, title and URL dropped) and pydantic's rewritten into gaitopt's form by the
  prototype's message layer, and whether that one keeps the field path and every number of
  gaitopt's (the allowed range);
* **time per call** (``timeit``, best of 5): valid options, bad options (the error and its
  message), one gait-file phase of 16 knots from plain lists;
* **import**: cold ``python -c ...`` wall time, median of ``--runs`` (default 10) fresh
  processes, of ``import gaitopt``, ``from gaitopt import GaitOptions``, the same with
  ``import pydantic`` first, ``import pydantic`` alone and the prototype module (pydantic and
  the models' schemas built), the cases taken in turn, and ``-X importtime``'s total (sum of
  the self times, median of 3 processes).

Run: ``PYTHONPATH=src nice python bench/validation.py [--runs 10]`` (pydantic installed in the
same environment; without it only the hand-written figures are printed).
"""

from __future__ import annotations

import argparse
import ast
import dataclasses
import datetime
import math
import os
import platform
import statistics
import subprocess
import sys
import time
import timeit
from pathlib import Path
from typing import Any

import numpy as np

from gaitopt.gait.formulations.select import biped_for
from gaitopt.gait.options.gait_options import GaitOptions, GaitOptionsError, validate_options
from gaitopt.gait.options.model_defaults import options_for_model
from gaitopt.gait.record.fields import GaitFileError
from gaitopt.gait.record.parts import GaitPhase
from gaitopt.robot import load_model

ROOT = Path(__file__).resolve().parents[1]
GAIT = ROOT / "src" / "gaitopt" / "gait"
HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

try:
    import pydantic
    import validation_pydantic as proto
    from pydantic import ValidationError
except ImportError:  # pragma: no cover - the figures of one side only
    pydantic = None  # type: ignore[assignment]

#: (file, qualified names) of the hand-written checks; ``*`` is the whole module.
HAND_OPTIONS = [("options/gait_options.py", ["GaitOptionsError", "_finite", "_bounds",
                                             "validate_options", "GaitOptions.from_dict"])]
HAND_SCHEMA = [
    ("record/fields.py", ["*"]),
    ("record/checks.py", ["check_solver", "check_consistency", "SOLVER_KEYS"]),
    ("record/parts.py", ["GaitPhase.__post_init__", "GaitEvent.__post_init__",
                       "GaitSamples.__post_init__"]),
    ("record/file.py", ["Gait.__post_init__", "_gait_from_dict", "_major_version", "_with_path",
                      "_strings"]),
]
HAND_PHASE = [("record/fields.py", ["GaitFileError", "bad_field", "array_of", "_shape_text",
                                  "mapping_of", "check_increasing"]),
              ("record/parts.py", ["GaitPhase.__post_init__"]),
              ("record/file.py", ["_with_path", "_strings"])]
PROTO_OPTIONS = ["_fail", "_ordered", "Finite", "Positive", "NonNegative", "Fraction", "Bounds",
                 "PositiveBounds", "Knots", "OptionsModel", "_RULES", "path_of", "_INTERVALS",
                 "_interval", "one_line"]
PROTO_PHASE = ["_array", "_shape", "Arr", "Interpolation", "PhaseModel", "phase_line"]

#: Bad options (changes to the paper's options) as tests/gait/test_walking_errors.py has them.
BAD_OPTIONS: list[dict[str, Any]] = [
    {"speed": -1.0}, {"speed": 2.0}, {"speed": float("nan")}, {"speed": "0.3"},
    {"speed_bounds": (0.5, 0.1)}, {"knots": (3, 1)}, {"knots": (3.5, 2)},
    {"single_support_fraction": 1.3}, {"tol": 2.0}, {"transcription": "rk4"},
    {"torso_bounds": (0.1, 0.5)}, {"step_length": 5.0}, {"step_length": 0.9},
    {"step_time": 0.5, "step_length": 0.1}, {"step_time": 8.0},
    {"efficiency_positive": 0.0}, {"max_iter": 0}, {"friction": -0.5},
    {"min_stance_knee_flexion": 0.0}, {"single_support_fraction_bounds": (0.5, 0.9)},
    {"swing_clearance": 2.0},
]
#: Bad phases: (what, edit of the phase's plain data).
BAD_PHASES: list[tuple[str, Any]] = [
    ("q one row short", lambda d: d.update(q=d["q"][:-1])),
    ("t decreasing", lambda d: d.update(t=d["t"][::-1])),
    ("t with NaN", lambda d: d["t"].__setitem__(3, float("nan"))),
    ("u with a string", lambda d: d["u"][3].__setitem__(0, "x")),
    ("forces not the contacts", lambda d: d.update(contacts=["tip_1", "tip_2"])),
    ("force of 3 columns", lambda d: d["contact_forces"].update(
        tip_1=[r + [0.0] for r in d["contact_forces"]["tip_1"]])),
    ("empty name", lambda d: d.update(name="")),
    ("interpolation without states", lambda d: d["interpolation"].pop("states")),
    ("negative error estimate", lambda d: d["error_estimate"].__setitem__(0, -1.0)),
]


#: Run in a child: the time to import pydantic's model machinery, then to build the models.
SPLIT = """
import time, numpy, gaitopt.units
t0 = time.perf_counter()
from pydantic import BaseModel, Field, field_validator
t1 = time.perf_counter()
import validation_pydantic
t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""


# -- lines ------------------------------------------------------------------------------------

def code_lines(path: Path, names: list[str]) -> int:
    """Code lines of the named top-level definitions (``Class.method`` for a method, ``*`` for
    the whole module): no blank, comment-only or docstring lines."""
    text = path.read_text()
    tree = ast.parse(text)
    lines = text.splitlines()
    skip: set[int] = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr) \
                and isinstance(body[0].value, ast.Constant) and isinstance(body[0].value.value,
                                                                           str):
            skip.update(range(body[0].lineno, (body[0].end_lineno or body[0].lineno) + 1))
    for node in tree.body:  # attribute docstrings and ``#:`` comments: not code either
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant):
            skip.update(range(node.lineno, (node.end_lineno or node.lineno) + 1))

    def span(node: ast.AST) -> range:
        start = min([node.lineno, *(d.lineno for d in getattr(node, "decorator_list", []))])
        return range(start, (node.end_lineno or node.lineno) + 1)

    def defs(body: list[ast.stmt]) -> dict[str, ast.AST]:
        out: dict[str, ast.AST] = {}
        for node in body:
            if isinstance(node, ast.FunctionDef | ast.ClassDef):
                out[node.name] = node
            elif isinstance(node, ast.Assign | ast.AnnAssign):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                for t in targets:
                    if isinstance(t, ast.Name):
                        out[t.id] = node
        return out

    chosen: set[int] = set()
    top = defs(tree.body)
    for name in names:
        if name == "*":
            chosen.update(range(1, len(lines) + 1))
            continue
        head, _, member = name.partition(".")
        node = top[head]
        if member:
            node = defs(node.body)[member]  # type: ignore[attr-defined]
        chosen.update(span(node))
    return sum(1 for n in chosen if n not in skip and lines[n - 1].strip()
               and not lines[n - 1].strip().startswith(("#", "import ", "from ")))


def hand_lines(parts: list[tuple[str, list[str]]]) -> int:
    return sum(code_lines(GAIT / f, names) for f, names in parts)


def field_declarations(path: Path, cls: str) -> int:
    """The lines of ``cls``'s field declarations (``name: type = default``)."""
    tree = ast.parse(path.read_text())
    node = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == cls)
    return sum((s.end_lineno or s.lineno) - s.lineno + 1 for s in node.body
               if isinstance(s, ast.AnnAssign))


# -- messages ---------------------------------------------------------------------------------

def hand_options_message(model: Any, changes: dict[str, Any]) -> str:
    options = options_for_model(model, GaitOptions.paper(**changes))
    try:
        validate_options(options, biped_for(model, options))
    except GaitOptionsError as exc:
        return str(exc)
    return "(accepted)"


def options_input(model: Any, changes: dict[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """The prototype's input (the fields after the model's defaults) and context (the reach of
    the legs at the options' knee flexion)."""
    options = options_for_model(model, GaitOptions.paper())
    data = {f.name: getattr(options, f.name) for f in dataclasses.fields(options)}
    data.update(changes)
    biped = biped_for(model, options)
    flex = data["min_stance_knee_flexion"]
    reach = min(leg.reach(-flex) for leg in biped.legs) if biped is not None else math.inf
    return data, {"reach": reach}


def proto_options_messages(data: dict[str, Any], context: dict[str, Any]) -> tuple[str, str]:
    try:
        proto.OptionsModel.model_validate(data, context=context)
    except ValidationError as exc:
        return proto.default_line(exc), proto.one_line(exc, proto.OptionsModel)
    return "(accepted)", "(accepted)"


def phase_data(knots: int = 16, nq: int = 7, nu: int = 6, nx: int = 10) -> dict[str, Any]:
    """One phase's plain data (lists, as read from JSON), single support on tip_1."""
    rng = np.random.default_rng(0)
    rows = lambda n: rng.standard_normal((knots, n)).tolist()  # noqa: E731
    return {"name": "single_support", "contacts": ["tip_1"],
            "t": np.linspace(0.0, 0.5, knots).tolist(), "q": rows(nq), "qd": rows(nq),
            "qdd": rows(nq), "u": rows(nu), "contact_forces": {"tip_1": rows(2)},
            "state_names": [f"s{i}" for i in range(nx)], "x": rows(nx), "xdot": rows(nx),
            "interpolation": {"states": "cubic_hermite", "controls": "piecewise_linear"},
            "error_estimate": [1e-4] * (knots - 1)}


def hand_phase(data: dict[str, Any]) -> GaitPhase:
    """As the gait-file reader builds a phase (``gait_file._with_path``)."""
    fields = dict(data, contacts=tuple(data["contacts"]), state_names=tuple(data["state_names"]))
    try:
        return GaitPhase(**fields)
    except GaitFileError as exc:
        raise GaitFileError("<Gait>", f"phases[0].{exc.path}", exc.message) from None


def hand_phase_message(data: dict[str, Any]) -> tuple[str, str]:
    try:
        hand_phase(data)
    except GaitFileError as exc:
        return exc.path, exc.message
    return "", "(accepted)"


def proto_phase_message(data: dict[str, Any]) -> tuple[str, str]:
    try:
        proto.PhaseModel.model_validate(data)
    except ValidationError as exc:
        return proto.phase_line(exc, "phases[0]")
    return "", "(accepted)"


def keeps(hand: str, other: str, path: str) -> str:
    """Whether ``other`` names ``path`` and every number of ``hand`` (the allowed range)."""
    numbers = [w.strip("()[],:") for w in hand.replace(",", " ").split()]
    numbers = [w for w in numbers if w and w.lstrip("-").replace(".", "", 1).isdigit()]
    missing = [n for n in numbers if n not in other]
    if path not in other:
        return "no path"
    return "yes" if not missing else f"no ({', '.join(missing)})"


# -- timing -----------------------------------------------------------------------------------

def per_call(fn: Any, number: int) -> float:
    """Best of 5 of ``number`` calls, seconds per call."""
    return min(timeit.repeat(fn, number=number, repeat=5)) / number


def cold(codes: list[str], runs: int) -> dict[str, list[float]]:
    """Wall times (s) of ``python -c code`` in fresh processes, ``runs`` of each, the codes
    taken in turn (so that a change of the machine's load falls on all of them alike)."""
    times: dict[str, list[float]] = {code: [] for code in codes}
    for _ in range(runs):
        for code in codes:
            start = time.perf_counter()
            subprocess.run([sys.executable, "-c", code], check=True, env=child_env())
            times[code].append(time.perf_counter() - start)
    return times


def importtime_total(code: str) -> tuple[float, int]:
    """``-X importtime``'s sum of self times (s) and module count, one fresh process."""
    out = subprocess.run([sys.executable, "-X", "importtime", "-c", code], check=True,
                         env=child_env(), capture_output=True, text=True).stderr
    selfs = [int(line.split("|")[0].split(":")[1]) for line in out.splitlines()
             if line.startswith("import time:") and "self [us]" not in line]
    return sum(selfs) / 1e6, len(selfs)


def child_env() -> dict[str, str]:
    path = os.pathsep.join([str(ROOT / "src"), str(HERE), os.environ.get("PYTHONPATH", "")])
    return {**os.environ, "PYTHONPATH": path}


def machine() -> str:
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        text = ""
    cpu = next((line.split(":", 1)[1].strip() for line in text.splitlines()
                if line.startswith("model name")), "?")
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                            capture_output=True, text=True).stdout.strip()
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    return (f"commit {commit}, {datetime.datetime.now(datetime.UTC):%Y-%m-%d %H:%M} UTC, "
            f"{os.cpu_count()} cores ({cpu}), load {load}, Python {platform.python_version()}, "
            f"numpy {np.__version__}, pydantic "
            f"{pydantic.VERSION if pydantic is not None else 'not installed'}")


def ratio(a: float, b: float) -> str:
    return f"{a / b:.2f}x" if b else "-"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10, help="fresh processes per import figure")
    args = parser.parse_args()
    print(f"bench/validation.py: {machine()}")
    have = pydantic is not None
    model = load_model("five-link")

    print("\n== lines of code (no blank, comment or docstring lines)")
    h_opt, h_schema, h_phase = (hand_lines(HAND_OPTIONS), hand_lines(HAND_SCHEMA),
                                hand_lines(HAND_PHASE))
    print(f"hand-written: options {h_opt}, gait-file schema {h_schema} (of which one phase and "
          f"its helpers {h_phase}); total {h_opt + h_schema}")
    if have:
        proto_file = HERE / "validation_pydantic.py"
        p_opt_all = code_lines(proto_file, PROTO_OPTIONS)
        decl = field_declarations(proto_file, "OptionsModel")
        p_phase = code_lines(proto_file, PROTO_PHASE)
        print(f"pydantic prototype: options {p_opt_all - decl} + {decl} field declarations "
              f"(the dataclass has them too) = {p_opt_all}, ratio {ratio(p_opt_all - decl, h_opt)}"
              f" of the hand-written checks; one phase {p_phase}, ratio {ratio(p_phase, h_phase)}")

    print("\n== options: the same bad input (changes to GaitOptions.paper(), five-link)")
    kept = 0
    for changes in BAD_OPTIONS:
        hand = hand_options_message(model, changes)
        print(f"- {changes}\n    gaitopt : {hand}")
        if have:
            data, context = options_input(model, changes)
            default, line = proto_options_messages(data, context)
            path = hand.split(" ", 1)[0].rstrip(":")
            verdict = keeps(hand, line, path)
            kept += verdict == "yes"
            print(f"    pydantic: {default}\n    rewritten: {line}\n    path and range kept: "
                  f"{verdict}")
    if have:
        print(f"path and every number kept by the rewritten message: {kept} of "
              f"{len(BAD_OPTIONS)}")

    print("\n== a gait-file phase: the same bad input")
    kept = 0
    for what, edit in BAD_PHASES:
        data = phase_data()
        edit(data)
        hpath, hmsg = hand_phase_message(data)
        print(f"- {what}\n    gaitopt : {hpath}: {hmsg}")
        if have:
            ppath, pmsg = proto_phase_message(data)
            same = ppath == hpath
            kept += same
            print(f"    pydantic: {ppath}: {pmsg}\n    same path: {'yes' if same else 'no'}")
    if have:
        print(f"same field path: {kept} of {len(BAD_PHASES)}")

    print("\n== time per call (best of 5)")
    options = options_for_model(model, GaitOptions.paper())
    biped = biped_for(model, options)
    bad = options_for_model(model, GaitOptions.paper(speed=-1.0))
    phase = phase_data()

    def hand_bad() -> str:
        try:
            validate_options(bad, biped)
        except GaitOptionsError as exc:
            return str(exc)
        return ""

    rows = [("valid options", lambda: validate_options(options, biped), 2000),
            ("bad options (speed -1), with its message", hand_bad, 2000),
            ("one phase, 16 knots, from lists", lambda: hand_phase(phase), 500)]
    if have:
        data, context = options_input(model, {})
        bad_data, _ = options_input(model, {"speed": -1.0})

        def proto_bad() -> str:
            try:
                proto.OptionsModel.model_validate(bad_data, context=context)
            except ValidationError as exc:
                return proto.one_line(exc, proto.OptionsModel)
            return ""

        proto_bad()  # the interval table is built on the first error, before timing
        others = [lambda: proto.OptionsModel.model_validate(data, context=context), proto_bad,
                  lambda: proto.PhaseModel.model_validate(phase)]
        marker = proto.OptionsModel.model_validate(data, context=context).speed_bounds
        print(f"(a model default given to the prototype comes back as "
              f"{type(marker).__name__}: pydantic drops gaitopt's follows-the-model marker)")
    for i, (label, fn, number) in enumerate(rows):
        t_hand = per_call(fn, number)
        line = f"{label:42s} gaitopt {t_hand * 1e6:8.1f} us"
        if have:
            t_proto = per_call(others[i], number)
            line += f"   pydantic {t_proto * 1e6:8.1f} us   ratio {ratio(t_proto, t_hand)}"
        print(line)

    print(f"\n== import, cold process: median of {args.runs} (wall s, the cases in turn), and -X "
          "importtime's total (sum of self times, median of 3, s; modules)")
    cases = [("python -c pass", "pass"), ("import gaitopt", "import gaitopt"),
             ("from gaitopt import GaitOptions", "from gaitopt import GaitOptions"),
             ("from gaitopt import GaitOptions, Gait", "from gaitopt import GaitOptions, Gait")]
    if have:
        cases += [("import pydantic", "import pydantic"),
                  ("from pydantic import BaseModel", "from pydantic import BaseModel"),
                  ("import pydantic; import gaitopt", "import pydantic; import gaitopt"),
                  ("import pydantic; from gaitopt import GaitOptions",
                   "import pydantic; from gaitopt import GaitOptions"),
                  ("the prototype (pydantic + its models)", "import validation_pydantic"),
                  ("the prototype; from gaitopt import GaitOptions",
                   "import validation_pydantic; from gaitopt import GaitOptions")]
    if have:
        cases += [("import gaitopt.cli (every gaitopt command)", "import gaitopt.cli"),
                  ("the prototype; import gaitopt.cli",
                   "import validation_pydantic; import gaitopt.cli")]
    else:
        cases += [("import gaitopt.cli (every gaitopt command)", "import gaitopt.cli")]
    samples = cold([code for _, code in cases], args.runs)
    wall = {code: statistics.median(t) for code, t in samples.items()}
    for label, code in cases:
        totals = [importtime_total(code) for _ in range(3)]
        total = statistics.median(t for t, _ in totals)
        print(f"{label:50s} {wall[code]:.3f} s (min {min(samples[code]):.3f})   importtime "
              f"{total:.3f} s ({totals[0][1]} modules)")
    if have:
        for base, withp in (("import gaitopt", "import pydantic; import gaitopt"),
                            ("from gaitopt import GaitOptions",
                             "import validation_pydantic; from gaitopt import GaitOptions"),
                            ("import gaitopt.cli",
                             "import validation_pydantic; import gaitopt.cli")):
            print(f"{withp!r} against {base!r}: +{wall[withp] - wall[base]:.3f} s, ratio "
                  f"{ratio(wall[withp], wall[base])}")
        split = [subprocess.run([sys.executable, "-c", SPLIT], check=True, env=child_env(),
                                capture_output=True, text=True).stdout.split()
                 for _ in range(args.runs)]
        base_t, models_t = (statistics.median(float(r[i]) for r in split) for i in (0, 1))
        print(f"in a process that has numpy and gaitopt.units: pydantic's BaseModel imported in "
              f"{base_t:.3f} s, the prototype's models built in {models_t:.3f} s (medians)")


if __name__ == "__main__":
    main()
