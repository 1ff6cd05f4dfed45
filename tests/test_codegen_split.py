"""Generated C split into chunk functions (``gaitopt.codegen.split_straight_line``): the split
library computes exactly what the whole one computes (the same operations in the same order,
compiled without contraction of multiply-adds, so bitwise on any machine), whatever the
chunk size; code that is not straight-line is left as it is; a bad chunk size is refused."""

from __future__ import annotations

import re
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from gaitopt import codegen

#: The same flags for the whole and the split library: exact IEEE arithmetic in program
#: order (no fused multiply-add, which would differ where a chunk boundary cuts a product
#: from its sum).
EXACT = ("-O0", "-ffp-contract=off", "-fPIC", "-shared")

pytestmark = pytest.mark.skipif(not codegen.has_compiler(), reason="no C compiler")


@pytest.fixture(autouse=True)
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("GAITOPT_CACHE", str(tmp_path))
    return tmp_path


def functions() -> list[ca.Function]:
    """A point-like function of 6 inputs (two outputs, sin/cos chains that make CasADi reuse
    its local variables many times), its Jacobian and the Hessian of a weighted sum of its
    outputs, as :mod:`gaitopt.ocp.pointwise` derives them."""
    z = ca.SX.sym("z", 6)
    a, b = z[0], z[1]
    for k in range(12):
        a, b = ca.sin(a * z[2 + k % 4] + b), ca.cos(b - 0.3 * a) * z[(k + 1) % 6]
    y = ca.vertcat(a * b, a + ca.exp(0.1 * b) * z[5], ca.sqrt(1 + a * a) - b)
    mu = ca.SX.sym("mu", 3)
    jac = ca.jacobian(y, z)
    hess, _ = ca.hessian(ca.dot(mu, y), z)
    return [ca.Function("f", [z], [y], ["z"], ["y"]),
            ca.Function("f_jac", [z], list(ca.cse([y, jac])), ["z"], ["y", "J"]),
            ca.Function("f_hess", [z, mu], list(ca.cse([jac, hess])), ["z", "mu"], ["J", "H"])]


def load(source: str, name: str, fns: list[ca.Function]) -> list[ca.Function]:
    path = codegen.compile_library(source, name, flags=EXACT)
    return [ca.external(f.name(), str(path)) for f in fns]


def outputs(f: ca.Function, args: list[np.ndarray]) -> list[np.ndarray]:
    return [np.array(r) for r in f.call([ca.DM(a) for a in args])]


@pytest.mark.parametrize("statements", [1, 7, 100])
def test_the_split_library_computes_exactly_what_the_whole_one_does(statements: int) -> None:
    fns = functions()
    source = codegen.generate_source(fns, "whole")
    split = codegen.split_straight_line(source, statements)
    n_statements = len(re.findall(r"^  a\d+=", source, flags=re.M))
    assert n_statements > 3 * 100  # every chunk size below splits the Hessian
    assert "_chunk" in split and "GAITOPT_NOINLINE" in split
    whole_fns = load(source, "whole", fns)
    split_fns = load(split, "split", fns)
    rng = np.random.default_rng(3)
    for _ in range(5):
        z, mu = rng.uniform(-1.5, 1.5, 6), rng.uniform(-2, 2, 3)
        for whole, part, original in zip(whole_fns, split_fns, fns, strict=True):
            args = [z, mu][:original.n_in()]
            expected = outputs(whole, args)
            got = outputs(part, args)
            for e, g in zip(expected, got, strict=True):
                assert np.array_equal(e, g), original.name()
            # and both are CasADi's own evaluation, to rounding
            for e, r in zip(expected, outputs(original, args), strict=True):
                np.testing.assert_allclose(e, r, rtol=1e-12, atol=1e-12)


def test_short_functions_are_left_whole() -> None:
    source = codegen.generate_source(functions(), "whole")
    assert codegen.split_straight_line(source, 10**9) == source


def test_code_that_is_not_straight_line_is_left_whole() -> None:
    """An MX function calling another function: its C uses the work vectors and calls, so it
    is not split (the straight-line function it calls is)."""
    inner = functions()[0]
    x = ca.MX.sym("x", 6)
    outer = ca.Function("outer", [x], [inner(x) * 2 + inner(2 * x)])
    source = codegen.generate_source([outer], "calls")
    split = codegen.split_straight_line(source, 5)
    calling = re.search(r"/\* outer:.*?\n(static int casadi_f\d+\(.*?\n\}\n)", split, re.S)
    assert calling is not None and "_chunk" not in calling.group(1)
    assert "_chunk" in split  # the called function, straight-line, is split
    whole = load(source, "calls", [outer])[0]
    part = load(split, "calls_split", [outer])[0]
    z = np.linspace(-1, 1, 6)
    assert np.array_equal(outputs(whole, [z])[0], outputs(part, [z])[0])


def test_a_function_without_its_end_is_left_as_it_is() -> None:
    head = ("static int casadi_f0(const casadi_real** arg, casadi_real** res, casadi_int* iw, "
            "casadi_real* w, int mem) {")
    cut = "\n".join([head, "  casadi_real a0;", *["  a0=(a0+1.);"] * 5])
    assert codegen.split_straight_line(cut, 2) == cut


@pytest.mark.parametrize("bad", [0, -3])
def test_a_chunk_size_below_one_is_refused(bad: int) -> None:
    with pytest.raises(ValueError, match=r"statements: .*allowed: an integer >= 1"):
        codegen.split_straight_line("", bad)
