"""Makes tests/data/ram_rough_tamaas.npz, the second method's answer on the adhesive rough path of
tests/test_ram_solver.py: Tamaas 2.9.0 (PyPI ``tamaas``; PolonskyKeerRey on the gap with its
ExponentialAdhesionFunctional, tolerance 1e-12), run in its own environment:

    python3 -m venv /work/venvs/tamaas && /work/venvs/tamaas/bin/pip install tamaas numpy scipy
    /work/venvs/tamaas/bin/python tests/data/make_ram_rough_tamaas.py

Problem: benchmarks/peer_aspher.py's surface on 64² (its heights ×200), cell L = 64 (dx = 1), E* = 2 (κ = 0.5),
W = 1, ρ = 1 ε, mean gaps 11.5, 7.5, 3.5, 7.5, 11.5 ε, each solve from the last.  Stored: the heights, the
path, per step the mean pressure, the contact fraction (gap <= 1e-9 rms) and the gap field."""
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "benchmarks"))
from peer_aspher import surface  # noqa: E402

import tamaas as tm  # noqa: E402

n, L = 64, 64.0
path = np.array([11.5, 7.5, 3.5, 7.5, 11.5])
h = 200.0 * surface(n)
surf = np.ascontiguousarray(h - h.mean())
model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [L, L], [n, n])
model.E, model.nu = 2.0, 0.0
solver = tm.PolonskyKeerRey(model, surf, 1e-12, tm.PolonskyKeerRey.gap, tm.PolonskyKeerRey.gap)
adh = tm.ExponentialAdhesionFunctional(surf)
adh.parameters = {"rho": 1.0, "surface_energy": 1.0}
solver.addFunctionalTerm(adh)
solver.setMaxIterations(50000)
mp, area, gaps = [], [], []
for g in path:
    solver.solve(float(g))
    gap = np.asarray(model.displacement) - surf
    mp.append(float(np.asarray(model.traction).mean()))
    area.append(float(np.mean(gap <= 1e-9 * h.std())))
    gaps.append(gap.astype(np.float32)) if g == 3.5 else None
np.savez_compressed(os.path.join(HERE, "ram_rough_tamaas.npz"), h=h, path=path, mean_p=np.array(mp),
                    area=np.array(area), gap=gaps[0], tamaas=tm.__version__)
print(mp, area)
