# %% [markdown]
# # How close may two Delta robots stand on one conveyor?
#
# A notebook-shaped example of `delta_collide` (run it as a script, or cell by cell in a
# notebook): for a few base spacings, the clearance the seeded pick-and-place programmes
# keep, how often the robots collide over random configurations, what a table of the chosen
# spacing proves, and a closed-loop run with coordination.
#
#     pip install ./python matplotlib
#     python examples/line_layout.py [output directory]
#
# Lengths in mm; each robot's TCP in its own machine coordinate system.

# %%
import sys
from pathlib import Path

import numpy as np

import delta_collide as dc

out_dir = Path(sys.argv[1] if len(sys.argv) > 1 else "line_layout_out")
out_dir.mkdir(parents=True, exist_ok=True)


def cell_at(spacing_mm: float) -> dc.Cell:
    """Two thesis robots `spacing_mm` apart along the conveyor (x), arms alike."""
    return dc.Cell.from_toml(
        f'name = "line {spacing_mm:g}"\n'
        '[[robot]]\nname = "A"\n'
        f'[[robot]]\nname = "B"\nplacement = {{ alpha_deg = 0.0, t = [{spacing_mm!r}, 0.0, 0.0] }}\n'
    )


# %% [markdown]
# ## Clearance of a programme at each spacing
# `simulate` draws the same seeded programmes as `delta-collide simulate`; its `programmes`
# are each robot's TCP per programme tick. Run as programmed (no override), the smallest
# clearance along them says how close the robots come.

# %%
rng = np.random.default_rng(1)
rows = []
for spacing in (350.0, 400.0, 450.0, 500.0, 550.0):
    cell = cell_at(spacing)
    prog = dc.simulate(cell, mode="free", seed=1, ticks=1500)["programmes"]
    tcps = np.ascontiguousarray(prog.transpose(1, 0, 2))  # (ticks, robots, 3)
    clearance = dc.clearance(cell, tcps)
    random = rng.uniform([-300, -300, -650], [300, 300, -300], (20_000, 2, 3))
    k = dc.check(cell, random)
    share = k.collide[k.reachable].mean()
    rows.append((spacing, np.nanmin(clearance), share))
    print(f"spacing {spacing:5.0f} mm: programme clearance >= {np.nanmin(clearance):8.2f} mm, "
          f"random reachable configurations colliding {100 * share:5.2f} %")

spacings, least, shares = map(np.array, zip(*rows))
# Further apart, the robots can meet less often.
assert shares[0] >= shares[-1]

# %% [markdown]
# ## A table for 450 mm, its quilt and what it proves
# A clearance table at k = 16 builds in about a second; `quilt` draws its labels over slices
# of robot A's workspace with robot B's TCP fixed.

# %%
cell = cell_at(450.0)
table = dc.Table.build(cell, 16, "clearance", progress=lambda done, total: None)
table.save(out_dir / "line450.dct")
print(table, table.inspect()["clearance_levels_mm"])
tcps = np.ascontiguousarray(rng.uniform([-300, -300, -650], [300, 300, -300], (50_000, 2, 3)))
bound = table.clearance_bound(tcps)
exact = dc.clearance(cell, tcps)
proved = np.isfinite(bound)
assert (bound[proved] <= exact[proved]).all()  # a certified lower bound, never above
print(f"table proves >= 20 mm for {100 * np.mean(bound >= 20):.1f} % of random configurations")

try:
    import matplotlib  # noqa: F401

    have_matplotlib = True
except ImportError:
    have_matplotlib = False

if have_matplotlib:
    dc.quilt(table, tcp_b=[-100.0, 0.0, -450.0], zs=(-350.0, -450.0, -520.0), path=out_dir / "quilt.png")
    dc.render(cell, [[120.0, 0.0, -450.0], [-120.0, 0.0, -450.0]], path=out_dir / "render.png")

# %% [markdown]
# ## Where would it stop? The protective verdict and a closed-loop run
# The programme run tick by tick through the protective verdict: STOP ticks, and how far the
# robots would still travel; then the closed-loop benchmark with coordination.

# %%
prog = dc.simulate(cell, mode="free", seed=2, ticks=800)["programmes"]
run = np.ascontiguousarray(prog.transpose(1, 0, 2))
p = dc.protective(cell, run)
stops = np.mean(p.verdict == dc.VERDICT_STOP)
print(f"protective verdict along the programme: {100 * stops:.1f} % STOP ticks, "
      f"largest stopping distance {np.max(p.protective_mm):.1f} mm")
# FREE only where the robots are apart now.
assert (p.clearance[p.verdict == dc.VERDICT_FREE] > 0).all()

r = dc.simulate(cell, mode="coordinate", seed=2, ticks=1500)
print(f"coordinated: throughput {r['throughput']:.3f}, {r['stop_events']} STOP events, "
      f"{r['contact_ticks']} contact ticks")
assert r["contact_ticks"] == 0
if have_matplotlib:
    dc.plot_run(p, path=out_dir / "protective.png")
    dc.plot_run(r, path=out_dir / "closed_loop.png")
print(f"pictures and the table in {out_dir}/")
