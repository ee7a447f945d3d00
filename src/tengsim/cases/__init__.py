"""Applications built on the core: each case package composes shapes, laws, runs and device models.

``tengsim.cases.paper`` is the paper (Figs. 3-5, 7, 8 and ``tengsim reproduce``); the core modules
(``tengsim.run.simulate``, ``tengsim.device``, ...) never import a case.
"""
