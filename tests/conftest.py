"""Settings every test run shares, so the suite gives the same verdict on any machine.

* BLAS runs on one thread: a threaded BLAS sums in an order that depends on the thread count,
  and two pytest workers on two cores are the parallelism the suite wants. The Makefile sets
  the same variables before Python starts; these defaults cover a bare ``pytest`` run (they
  take effect where NumPy is not loaded yet).
* Hypothesis runs derandomised (the ``deterministic`` profile, the default): the same
  examples on every machine and every run, no example database. ``HYPOTHESIS_PROFILE=explore``
  searches with fresh random examples instead.

The tolerance rules the tests follow are in docs/testing.md.
"""

from __future__ import annotations

import os

for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

from hypothesis import HealthCheck, settings  # noqa: E402  (after the thread settings)

settings.register_profile("deterministic", derandomize=True, database=None, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("explore", deadline=None,
                          suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))
