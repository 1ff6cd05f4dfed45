"""gaitopt.gait.formulations: the two formulations of the walking problem, each one object
behind one protocol (``select``), their traits, the cost, and what their records share.

Each formulation is a sub-package: ``reduced/`` (the paper's reduced coordinates) and ``full/``
(full coordinates on any contact sequence), each with its ``physics``, its ``problem`` and the
``extract`` of a gait record from its solution."""
