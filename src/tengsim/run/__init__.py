"""One contact run: the plan (a [contact] table read and validated once, :mod:`tengsim.run.plan`), one grid's
approach–retraction run (:mod:`tengsim.run.simulate`) and automatic grid refinement (:mod:`tengsim.run.resolve`)."""
