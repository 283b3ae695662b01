"""PRT on a batch of lots, one model per lot: the differential harness's side of Esri's engine.

This file runs in PyPRT's side environment, not in grammarc's (PyPRT and grammarc's dependencies do not
share a Python), so it imports nothing of grammarc, nor numpy: only the standard library, PyPRT and the
kit's ``prt_reference.py``, whose footprint mapping and statistics it reuses so that the harness measures
PRT exactly as the kit's reference records do.

    PRT_PYTHON prt_batch.py KIT RPK LOTS.geojson OUT

``LOTS.geojson`` is a FeatureCollection; each feature is one lot, named by ``properties.name``, and its other
properties are the lot's rule attributes (numbers as floats, booleans, strings) plus ``seed``, the shape's
random seed. All lots are generated in one ``generate_model`` call (one with polygons and reports, one
triangulated), as CityEngine generates a selection of lots. ``OUT.json`` gets, per lot name, the fields of
a kit record (``n_faces``, ``n_triangles``, ``surface_area``, ``bbox_min``, ``bbox_max``, ``report``,
``cga_messages``) and ``triangles`` = [first, count] into ``OUT.tri``: little-endian float64 triangle
corners in PRT's world, 9 numbers per triangle. A lot PRT makes no model of gets ``error``.
"""

import json
import os
import sys
from array import array


def main(argv):
    kit, rpk, lots_path, out = argv
    sys.path.insert(0, kit)
    import prt_reference as ref

    pyprt = ref.import_pyprt()
    rpk = os.path.abspath(rpk)
    with open(lots_path, encoding="utf-8") as file:
        features = json.load(file)["features"]
    names = [f["properties"]["name"] for f in features]
    shapes = [ref.load_footprint(lots_path, feature=name) for name in names]
    attrs = [_attributes(f["properties"]) for f in features]
    generator = pyprt.ModelGenerator([ref.make_initial_shape(pyprt, s) for s in shapes])
    models = generator.generate_model(attrs, rpk, ref.PYENCODER, {"emitGeometry": True, "emitReport": True})
    triangulated = generator.generate_model(attrs, rpk, ref.PYENCODER,
                                            {"emitGeometry": True, "emitReport": False, "triangulate": True})
    results = {name: {"error": "PRT generated no model"} for name in names}
    for model in models:
        name = names[model.get_initial_shape_index()]
        record = ref.polygon_stats([model])
        record["report"] = ref._clean(model.get_report())
        record["cga_messages"] = [m.strip()[:300] for m in model.get_cga_errors()[:5]]
        results[name] = record
    corners = array("d")
    for model in triangulated:
        name = names[model.get_initial_shape_index()]
        if "error" in results[name]:
            continue
        results[name].update(ref.triangle_stats([model]))
        first = len(corners) // 9
        _add_triangles(model, corners)
        results[name]["triangles"] = [first, len(corners) // 9 - first]
    if sys.byteorder != "little":
        corners.byteswap()
    with open(out + ".tri", "wb") as file:
        corners.tofile(file)
    with open(out + ".json", "w", encoding="utf-8") as file:
        json.dump({"pyprt": ref.pyprt_version(), "lots": results}, file)


def _attributes(properties):
    """A lot's properties as PRT's attributes: numbers as floats, ``seed`` as an int, no ``name``."""
    out = {}
    for key, value in properties.items():
        if key == "name":
            continue
        if key == "seed":
            out[key] = int(value)
        elif isinstance(value, (int, float)) and not isinstance(value, bool):
            out[key] = float(value)
        else:
            out[key] = value
    return out


def _add_triangles(model, corners):
    """Append the model's triangles (its faces of three vertices) to ``corners``, 9 floats each."""
    vertices, position = model.get_vertices(), 0
    indices = model.get_indices()
    for count in model.get_faces():
        if count == 3:
            for i in indices[position:position + 3]:
                corners.extend(vertices[3 * i:3 * i + 3])
        position += count


if __name__ == "__main__":
    main(sys.argv[1:])
