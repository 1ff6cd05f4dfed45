"""gaitopt.gait.guess: the naive first guesses of a cold start, from geometry alone."""
