"""gaitopt.gait.formulations.full: full coordinates ``[q, qd]`` on any contact sequence."""
