"""gaitopt.gait.formulations.reduced: the paper's reduced coordinates of a five-link biped."""
