"""gaitopt.gait.sequence: contact sequences (phases, events, reading and checking one), the
built-in sequences, and the free phase fractions (each phase's share of the step)."""
