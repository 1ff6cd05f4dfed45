"""The checks of :func:`gaitopt.analysis.verify.verify_gait`, one module per kind.

* :mod:`.check`: the :class:`~.check.Check` record and the table of stable check ids
  (:data:`~.check.CHECKS`) with their default limits;
* :mod:`.knots`: the full-coordinate fields at every knot (equations of motion, held contacts,
  phase states, parameters, contact forces);
* :mod:`.integration`: re-integration of the saved motion;
* :mod:`.events`: heel strike, liftoff and periodicity;
* :mod:`.samples`: the dense samples and the constraints checked on them.
"""
