"""gaitopt.gait.solve: the staged solve (its run, its continuation stages, the NLP cache), its
accuracy and refinement, the diagnosis of a failure, and the gait record of a solution."""
