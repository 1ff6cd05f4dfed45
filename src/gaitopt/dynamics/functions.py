"""The dynamics algorithms as CasADi Functions, optionally compiled to C.

Each builder traces the scalar algorithms once on ``SX`` symbols and returns a
``casadi.Function`` with named inputs and outputs (shapes are columns):

=============================  ==============================  ==================================
builder                        inputs                          outputs
=============================  ==============================  ==================================
forward_dynamics_function      q (nq), qd (nq), tau|u          qdd (nq)
contact_dynamics_function      q, qd, tau|u                    qdd (nq), forces (2nc),
                                                               Lambda (2nc x 2nc)
impact_function                q, qd_minus                     qd_plus (nq), impulses (2nc)
liftoff_function               q, qd_minus, magnitude (1)      qd_plus (nq), impulse_lifting (2),
                                                               impulses_held (2 n_held)
=============================  ==============================  ==================================

``inputs="u"`` takes actuator torques ``u`` (nu) instead of generalized forces ``tau`` (nq) and
maps them with :func:`.actuation.generalized_forces` (ankle torques act only for held
contacts; never in free dynamics).

``compiled=True`` generates C code, compiles it with :func:`gaitopt.codegen.compile_functions`
(cached on disk by the generated source, which depends on the model content) and returns the
loaded external Function, with the same inputs and outputs. Every result is also cached
in-process by ``(model.content_hash(), builder, arguments, options)``, and every symbolic
function on disk (:mod:`gaitopt.dynamics.function_cache`, keyed by the same and by the gaitopt
sources): tracing the seven-link biped's contact dynamics of a gait's phases took 0.6 s of a
``gaitopt solve`` process (in ``verify``), loading them takes milliseconds.
"""

from __future__ import annotations

import re
import threading
from collections.abc import Callable, Sequence
from typing import Any, Literal

import casadi as ca

from gaitopt.codegen import compile_functions
from gaitopt.dynamics.aba import aba
from gaitopt.dynamics.actuation import generalized_forces_scalars
from gaitopt.dynamics.backend import as_scalars
from gaitopt.dynamics.contact import contact_dynamics_scalars
from gaitopt.dynamics.function_cache import disk_cached, function_file
from gaitopt.dynamics.impact import impact_scalars, liftoff_impulse
from gaitopt.dynamics.tree import contact_names, hold_specs
from gaitopt.robot.model import RobotModel

Inputs = Literal["tau", "u"]

_CACHE: dict[tuple[Any, ...], ca.Function] = {}
_LOCK = threading.Lock()


def _identifier(text: str) -> str:
    return re.sub(r"\W", "_", text)


def _cached(model: RobotModel, key: tuple[Any, ...], compiled: bool,
            build: Callable[[], ca.Function]) -> ca.Function:
    full_key = (model.content_hash(), *key, compiled)
    with _LOCK:
        hit = _CACHE.get(full_key)
    if hit is not None:
        return hit
    function = disk_cached(function_file("dynamics", (model.content_hash(), *key)), build)
    if compiled:
        library = _identifier(f"gaitopt_{model.name}_{model.content_hash()}_{function.name()}")
        function = compile_functions([function], library)[function.name()]
    with _LOCK:
        _CACHE.setdefault(full_key, function)
        return _CACHE[full_key]


def clear_cache() -> None:
    """Forget the in-process cache (the on-disk library cache is untouched)."""
    with _LOCK:
        _CACHE.clear()


def _torque_input(model: RobotModel, inputs: Inputs) -> ca.SX:
    if inputs == "tau":
        return ca.SX.sym("tau", model.nq)
    if inputs == "u":
        return ca.SX.sym("u", model.nu)
    raise ValueError(f"inputs must be 'tau' (generalized forces) or 'u' (actuator torques), "
                     f"got {inputs!r}")


def _tau(model: RobotModel, torque: ca.SX, inputs: Inputs, held: Sequence[str]) -> list[Any]:
    if inputs == "tau":
        return as_scalars(torque, model.nq, "tau")
    return generalized_forces_scalars(model, as_scalars(torque, model.nu, "u"), held)


def forward_dynamics_function(model: RobotModel, *, inputs: Inputs = "tau",
                              compiled: bool = False) -> ca.Function:
    """``forward_dynamics(q, qd, tau|u) -> qdd``: unconstrained dynamics by the ABA."""

    def build() -> ca.Function:
        q, qd = ca.SX.sym("q", model.nq), ca.SX.sym("qd", model.nq)
        torque = _torque_input(model, inputs)
        qdd = aba(model, q, qd, ca.vertcat(*_tau(model, torque, inputs, ())))
        return ca.Function("forward_dynamics", [q, qd, torque], [qdd],
                           ["q", "qd", inputs], ["qdd"], {"cse": True})

    return _cached(model, ("forward_dynamics", inputs), compiled, build)


def contact_dynamics_function(model: RobotModel, contacts: Sequence[str], *,
                              inputs: Inputs = "tau", compiled: bool = False) -> ca.Function:
    """``contact_dynamics_<contacts>(q, qd, tau|u) -> (qdd, forces, Lambda)`` with the tips
    ``contacts`` held (see :func:`.contact.contact_dynamics`; hold specs allowed)."""
    names = hold_specs(model, contacts)

    def build() -> ca.Function:
        q, qd = ca.SX.sym("q", model.nq), ca.SX.sym("qd", model.nq)
        torque = _torque_input(model, inputs)
        qdd, forces, lam = contact_dynamics_scalars(
            model, as_scalars(q, model.nq, "q"), as_scalars(qd, model.nq, "qd"),
            _tau(model, torque, inputs, names), names)
        n = len(forces)
        lam_sx = ca.vertcat(*[ca.horzcat(*row) for row in lam]) if n else ca.SX(0, 0)
        name = _identifier("contact_dynamics_" + "_".join(names) if names else
                           "contact_dynamics_none")
        return ca.Function(name, [q, qd, torque],
                           [ca.vertcat(*qdd), ca.vertcat(*forces) if n else ca.SX(0, 1),
                            lam_sx],
                           ["q", "qd", inputs], ["qdd", "forces", "Lambda"], {"cse": True})

    return _cached(model, ("contact_dynamics", names, inputs), compiled, build)


def impact_function(model: RobotModel, contacts: Sequence[str], *,
                    compiled: bool = False) -> ca.Function:
    """``impact_<contacts>(q, qd_minus) -> (qd_plus, impulses)`` (see :func:`.impact.impact`;
    hold specs allowed)."""
    names = hold_specs(model, contacts)
    if not names:
        raise ValueError("impact_function needs at least one contact")

    def build() -> ca.Function:
        q, qd = ca.SX.sym("q", model.nq), ca.SX.sym("qd_minus", model.nq)
        qd_plus, impulses = impact_scalars(model, as_scalars(q, model.nq, "q"),
                                           as_scalars(qd, model.nq, "qd_minus"), names)
        return ca.Function(_identifier("impact_" + "_".join(names)), [q, qd],
                           [ca.vertcat(*qd_plus), ca.vertcat(*impulses)],
                           ["q", "qd_minus"], ["qd_plus", "impulses"], {"cse": True})

    return _cached(model, ("impact", names), compiled, build)


def liftoff_function(model: RobotModel, lifting: str, held: Sequence[str] = (), *,
                     compiled: bool = False) -> ca.Function:
    """``liftoff_<lifting>(q, qd_minus, magnitude) -> (qd_plus, impulse_lifting,
    impulses_held)`` (see :func:`.impact.liftoff_impulse`; the sign of ``magnitude`` is not
    checked inside the Function: bound it ``>= 0`` in the optimization)."""
    (lift,) = contact_names(model, (lifting,), "lifting")
    held_names = hold_specs(model, held, "held")

    def build() -> ca.Function:
        q, qd = ca.SX.sym("q", model.nq), ca.SX.sym("qd_minus", model.nq)
        magnitude = ca.SX.sym("magnitude")
        sol = liftoff_impulse(model, q, qd, lift, magnitude, held_names)
        impulses_held = sol.impulses_held if held_names else ca.SX(0, 1)
        name = _identifier(f"liftoff_{lift}" + ("_holding_" + "_".join(held_names)
                                                 if held_names else ""))
        return ca.Function(name, [q, qd, magnitude],
                           [sol.qd_plus, sol.impulse_lifting, impulses_held],
                           ["q", "qd_minus", "magnitude"],
                           ["qd_plus", "impulse_lifting", "impulses_held"], {"cse": True})

    return _cached(model, ("liftoff", lift, held_names), compiled, build)
