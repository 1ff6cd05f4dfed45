"""gaitopt.gait.solve: the staged solve (its run, its continuation stages, the NLP cache), its
accuracy and refinement, the diagnosis of a failure, and the :class:`~gaitopt.gait.record.file.Gait`
of a run. The run and its stage records (:mod:`gaitopt.gait.solve.staged_run`) are internal:
users get the gait (docs/architecture.md, "One public result")."""
