"""The data model: the types every layer passes around, below all the others.

- ``grammar``: the checked grammar (its IR module, rule graph, assets and sources), what the compiler makes;
- ``lots``: footprints as ragged arrays, and the lots that were refused;
- ``records``: the chunks of instance records and leaf meshes the derivation hands to the writers;
- ``reports``: the values of ``report()`` per lot and over the city;
- ``assets``: asset meshes in their unit box, built in or loaded from the asset roots (``obj``: the OBJ
  geometry they are read from).

Readers make these, the derivation takes and makes them, writers and render take them: each imports them
from here, never from one another. A grammar holds its IR module, so the model sits on ``grammarc.ir``.
"""
