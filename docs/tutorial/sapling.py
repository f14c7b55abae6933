# The README's tutorial in Python: run from the checkout as
#   PYTHONPATH=build/python /usr/bin/python3 docs/tutorial/sapling.py
import sprig

tree = sprig.load("docs/tutorial/sapling.yaml", overrides={"branch": 35})
print(tree.summary())
print("defines:", tree.defines())

skeleton = tree.derive()
print(len(skeleton["starts"]), "internodes, the tallest tip at y =", round(float(skeleton["ends"][:, 1].max()), 2))

image = tree.render(320, 320)                 # a numpy array, (320, 320, 4) uint8
image.save("out/sapling_narrow.png")
print("out/sapling_narrow.png:", image.shape)

for part in tree.mesh(cell=0.01, simplify=0.0005):
    print(part["name"], len(part["triangles"]), "triangles")
