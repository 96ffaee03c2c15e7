"""A Warren truss bridge built from numpy arrays, solved by linkage, plotted with matplotlib.

    pip install ./python matplotlib      # from the repository's top folder
    python examples/python/truss.py      # writes truss.png (and truss.toml, the same scene for the CLI)

Node and member numbers are 1-based, as in the scene files: row i of `nodes` is node i + 1.
"""

import matplotlib

matplotlib.use("Agg")  # draw to a file, no window needed
import matplotlib.pyplot as plt
import numpy as np

import linkage

# Geometry: 6 panels of 2 m, 1.5 m deep. Bottom chord nodes 1..7, top chord nodes 8..13.
panels, width, depth = 6, 2.0, 1.5
bottom = np.column_stack([np.arange(panels + 1) * width, np.zeros(panels + 1)])
top = np.column_stack([(np.arange(panels) + 0.5) * width, np.full(panels, depth)])
nodes = np.vstack([bottom, top])
b = lambda i: i + 1                 # bottom node i (0-based) as a 1-based number
t = lambda i: panels + 2 + i        # top node i
members = np.array(
    [[b(i), b(i + 1)] for i in range(panels)]            # bottom chord
    + [[t(i), t(i + 1)] for i in range(panels - 1)]      # top chord
    + [[b(i), t(i)] for i in range(panels)]              # diagonals up
    + [[t(i), b(i + 1)] for i in range(panels)]          # diagonals down
)

steel = linkage.Material("steel", youngs_modulus=210e9, area=2e-3)   # Pa, m²
bridge = linkage.Body("bridge", nodes=nodes, members=members, material=steel)
bridge.support(nodes=[b(0)], fix=["x", "y"])          # pin at the left
bridge.support(nodes=[b(panels)], fix=["y"])          # roller at the right
inner = [b(i) for i in range(1, panels)]
bridge.load(nodes=inner, force=[0.0, -50e3])          # 50 kN down at each inner bottom node

scene = linkage.Scene("bridge", bodies=[bridge], steps=1)
scene.to_toml("truss.toml")                           # `linkage run truss.toml` runs the same
res = scene.run()                                      # in memory: nothing else is written
last = res.steps[-1].body("bridge")

# Check against statics: each support carries half the total load.
total = 50e3 * len(inner)
print(f"{scene.describe()}")
print(f"reactions at the supports: {last.reactions[b(0) - 1, 1]:.1f} N and {last.reactions[b(panels) - 1, 1]:.1f} N "
      f"(statics: {total / 2:.1f} N each)")
mid = b(panels // 2) - 1
print(f"mid-span deflection: {last.displacements[mid, 1] * 1e3:.3f} mm")
k = np.argmax(np.abs(last.axial_forces))
print(f"largest member force: member {k + 1}, {last.axial_forces[k] / 1e3:.1f} kN "
      f"({'tension' if last.axial_forces[k] > 0 else 'compression'})")

# Plot: undeformed in grey, deformed (magnified) coloured by axial force.
scale = 0.03 * np.ptp(nodes[:, 0]) / np.abs(last.displacements).max()
deformed = nodes + scale * last.displacements
fig, ax = plt.subplots(figsize=(10, 4))
norm = plt.Normalize(-np.abs(last.axial_forces).max() / 1e3, np.abs(last.axial_forces).max() / 1e3)
cmap = plt.get_cmap("coolwarm")
for (i, j), force in zip(members - 1, last.axial_forces):
    ax.plot(*nodes[[i, j]].T, color="0.8", lw=1, zorder=1)
    ax.plot(*deformed[[i, j]].T, color=cmap(norm(force / 1e3)), lw=2.5, zorder=2)
ax.plot(*deformed.T, "ko", ms=3, zorder=3)
for n in inner:
    x, y = deformed[n - 1]
    ax.annotate("", xy=(x, y), xytext=(x, y - 0.6), arrowprops=dict(arrowstyle="<-", color="k"))
fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, label="axial force, kN (tension +)")
ax.set_aspect("equal")
ax.set_xlabel("x, m")
ax.set_ylabel("y, m")
ax.set_title(f"Warren truss, 50 kN per inner node; displacements x{scale:.0f}")
fig.tight_layout()
fig.savefig("truss.png", dpi=120)
print("wrote truss.png and truss.toml")
