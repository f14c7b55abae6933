#!/usr/bin/python3
"""Independent reference for tests/assets/cpfg/query: cpfg's own turtle (interpret.c:
H = (0,1,0), L = (-1,0,0), U = (0,0,-1); change_dir rotates two vectors toward each other)
and the two productions of plant.l, stepped as cpfg steps them (queries filled before each
step and after the last one). Prints the final module string's query values."""
import numpy as np


def change_dir(v1, v2, s, c):
    return c * v1 + s * v2, c * v2 - s * v1


def run(angle_deg, steps=6):
    a = np.radians(angle_deg)
    H, L, U = np.array([0., 1, 0]), np.array([-1., 0, 0]), np.array([0., 0, -1])
    H, L = change_dir(H, L, np.sin(a), np.cos(a))          # '+'
    Hb, Ub = change_dir(H, U, 1.0, 0.0)                      # '&(90)' in the branch
    main_f = branch_f = 0
    for _ in range(steps):
        apex = main_f * H                                    # ?P after A (F(1) per grown step)
        tip = apex + branch_f * Hb                           # ?P after B
        grow_main = apex[1] < 2.5
        grow_branch = tip[2] > -2.5
        main_f += grow_main
        branch_f += grow_branch
    apex = main_f * H
    tip = apex + branch_f * Hb
    return main_f, branch_f, apex[:2], tip, Hb, L, Ub


for angle in (30, 45):
    m, b, p, q, h, l, u = run(angle)
    print(f"angle {angle}: main F {m}, branch F {b}, ?P {p.round(12)}, branch ?P {q.round(12)},"
          f" ?H {h.round(12)}, ?L {l.round(12)}, ?U {u.round(12)}")
