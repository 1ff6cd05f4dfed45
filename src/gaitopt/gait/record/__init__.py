"""gaitopt.gait.record: the gait record (``Gait``) and its file, its parts and their checks,
and values between its knots (numpy only: no CasADi, no other gait sub-package)."""
