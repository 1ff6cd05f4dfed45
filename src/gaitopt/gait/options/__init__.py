"""gaitopt.gait.options: the options of the walking problem (``GaitOptions``, their checks),
the defaults that follow the model, the model's scale, and the preflight checks of a model."""
