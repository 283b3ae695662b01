"""Make lots.geojson: the building footprints of Xkipche's groups, each with its control parameters.

The paper (Mueller et al. 2006) reconstructs the site from GIS data: building footprints (Figure 2) and
per building the "20 - 30 parameters" of its type, one of the 18 building types the archaeologists
recognized (Figure 3). Neither the survey nor the figures' pictures are in the paper's text, so this
script stands in for them from what the text says:

- Sites. Eight concentrations of buildings, groups A-H (section 3.1): B the ceremonial centre, A, C and
  D residential, the palace "in the center of group A". We lay each group out as Puuc groups are laid
  out, rectangular range buildings facing a plaza or courtyard from its sides, the palace between two
  courts of group A; B's plaza is the largest, with a shrine on a high platform. Distances between the
  groups are ours and shorter than on the site (so that one picture shows every building).
- Types. 18 parameter sets (``TYPES``) spanning what section 3 describes: one to seven doors of
  100-120 cm, single and double ranges, plain and colonette friezes (rules 20, 21), lattice, stepped
  fret and mosaic friezes, front and edge masks, one- to four-member moldings with or without
  colonettes (Figure 7), doors framed by columns, ventilators, platforms from low to high. Their names
  are ours; each lot's ``type`` names its set.
- Proportions. Puuc ranges are rows of rooms of about 3 x 5 m behind 0.6-0.8 m walls, each room with
  its own door: a building's length is its rooms (bays) times the bay width, its depth one or two rooms
  (single and double ranges); heights and moldings follow Figure 4's bands.

Every lot is a rectangle whose first edge is its front, the side facing its plaza (the grammar puts the
doors there); rings are counter-clockwise (RFC 7946). The section 5 remark "we do not use random
variations for the reconstruction" holds here too: no randomness, the script always writes the same
bytes.

    python make_lots.py [--out lots.geojson]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

#: Parameters every building type shares unless it says otherwise (see xkipche.cga for their meaning).
COMMON = {
    "platform_h": 0.6, "platform_margin": 1.2, "roof_h": 0.3, "wall_d": 0.7,
    "door_w": 1.1, "door_h": 2.2, "door_frame_w": 0.35, "jamb_a": 2.5, "door_frame": "jambs",
    "doors": 1, "back_doors": 0,
    "frieze_decoration": "none", "frieze_h": 1.6, "frieze_p": 0.05, "frieze_colonette_diameter": 0.22,
    "molding_colonette_diameter": 0.14, "mosaic_d": 0.12,
    "front_mask_w": 0.0, "edge_mask_w": 0.0, "mask_p": 0.55,
    "vent_w": 0.0, "vent_h": 0.3, "vent_spacing": 3.5,
}

#: Moldings as (height, apron_h, deco_h, reverse_apron_h, apron_p, rect_p): Figure 7's five parameters
#: and the molding's height (the rectangular member takes what the others leave). Pollock's kinds
#: (section 3.2): one member, two, three ("apron, rectangular member, reverse apron"), the binder of
#: colonettes between aprons, and Xkipche's four-member cornice (Figure 4, bottom right).
MOLDINGS = {
    "one": (0.35, 0.0, 0.0, 0.0, 0.25, 0.10),
    "two": (0.45, 0.18, 0.0, 0.0, 0.25, 0.12),
    "three": (0.50, 0.15, 0.0, 0.15, 0.30, 0.15),
    "binder": (0.60, 0.12, 0.26, 0.12, 0.30, 0.20),
    "four": (0.70, 0.15, 0.22, 0.18, 0.35, 0.22),
}

#: The 18 building types: name -> (bay width, depth, lower facade height, base, medial and cornice
#: molding kinds, and the parameters that differ from COMMON). The lower facade is the door and its
#: lintel ("directly below the medial molding", section 4.2).
TYPES = {
    "plain-room": (5.0, 5.6, 2.8, "one", "two", "three", {"door_w": 1.0}),
    "plain-range-2": (4.8, 6.0, 2.8, "one", "three", "three", {"doors": 2, "door_w": 1.05}),
    "plain-range-3": (4.6, 6.2, 2.9, "three", "three", "three", {"doors": 3}),
    "colonette-room": (5.2, 5.8, 2.9, "one", "three", "three",
                        {"frieze_decoration": "colonettes", "door_w": 1.15}),
    "colonette-range-3": (4.8, 6.4, 2.9, "three", "binder", "three",
                           {"doors": 3, "frieze_decoration": "colonettes"}),
    "colonette-range-5": (4.6, 6.4, 3.0, "binder", "binder", "four",
                           {"doors": 5, "frieze_decoration": "colonettes", "frieze_h": 1.8}),
    "binder-range": (5.0, 6.2, 2.9, "binder", "binder", "binder", {"doors": 3, "door_w": 1.2}),
    "double-range": (4.8, 10.6, 2.9, "three", "binder", "four",
                     {"doors": 3, "back_doors": 3, "frieze_decoration": "colonettes"}),
    "lattice-range": (5.0, 6.4, 2.9, "three", "three", "four",
                      {"doors": 3, "frieze_decoration": "lattice", "frieze_h": 1.4}),
    "fret-range": (5.4, 6.2, 2.9, "three", "three", "three",
                   {"doors": 2, "frieze_decoration": "frets", "frieze_h": 1.3}),
    "mosaic-range": (4.8, 6.6, 3.0, "binder", "binder", "four",
                     {"doors": 5, "frieze_decoration": "mosaic", "frieze_h": 1.6}),
    "corner-masks": (5.0, 6.4, 2.9, "three", "three", "three",
                     {"doors": 3, "edge_mask_w": 0.9, "frieze_h": 1.8}),
    "door-masks": (5.2, 6.4, 3.0, "three", "binder", "four",
                   {"doors": 3, "frieze_decoration": "colonettes", "front_mask_w": 2.0, "frieze_h": 1.8}),
    "ornate": (5.2, 7.0, 3.0, "binder", "binder", "four",
               {"doors": 3, "frieze_decoration": "mosaic", "front_mask_w": 2.0, "edge_mask_w": 0.9,
                "frieze_h": 1.9, "platform_h": 1.0}),
    "palace": (5.0, 11.0, 3.1, "binder", "four", "four",
               {"doors": 7, "back_doors": 5, "frieze_decoration": "mosaic", "front_mask_w": 2.2,
                "edge_mask_w": 1.0, "frieze_h": 2.2, "platform_h": 1.5, "door_w": 1.2}),
    "shrine": (6.0, 5.0, 2.9, "three", "binder", "four",
               {"frieze_decoration": "colonettes", "front_mask_w": 2.0, "platform_h": 4.0,
                "platform_margin": 1.6, "frieze_h": 1.8}),
    "columned-door": (5.6, 6.2, 2.9, "three", "binder", "three",
                      {"doors": 3, "door_frame": "columns", "door_frame_w": 0.4,
                       "frieze_decoration": "colonettes"}),
    "vented-range": (4.6, 6.0, 2.8, "two", "three", "three",
                     {"doors": 2, "vent_w": 0.5, "door_w": 1.0}),
}


def parameters(name: str) -> tuple[float, float, dict]:
    """Bay width, depth and the lot properties (every control parameter) of building type ``name``."""
    bay, depth, lower, base, medial, cornice, own = TYPES[name]
    props = {"type": name, **COMMON, **own}
    for band, kind in (("base", base), ("medial", medial), ("cornice", cornice)):
        height, apron_h, deco_h, revap_h, apron_p, rect_p = MOLDINGS[kind]
        props[f"{band}_molding_h"] = height
        props.update({f"{band}_apron_h": apron_h, f"{band}_deco_h": deco_h,
                      f"{band}_reverse_apron_h": revap_h, f"{band}_apron_p": apron_p,
                      f"{band}_rect_p": rect_p})
    props["building_h"] = round(props["base_molding_h"] + lower + props["medial_molding_h"]
                                + props["frieze_h"] + props["cornice_molding_h"], 3)
    return bay, depth, props


class Site:
    """Collects the lots as GeoJSON features; ``court`` adds a plaza and the buildings round it."""

    def __init__(self) -> None:
        self.features: list[dict] = []

    def lot(self, lot_id: str, x0: float, y0: float, x1: float, y1: float, front: str, props: dict) -> None:
        """A rectangle whose first edge is its side ``front`` ("S", "E", "N" or "W"), ring
        counter-clockwise."""
        corners = {"S": [(x0, y0), (x1, y0), (x1, y1), (x0, y1)],
                   "E": [(x1, y0), (x1, y1), (x0, y1), (x0, y0)],
                   "N": [(x1, y1), (x0, y1), (x0, y0), (x1, y0)],
                   "W": [(x0, y1), (x0, y0), (x1, y0), (x1, y1)]}[front]
        ring = [[round(x, 2), round(y, 2)] for x, y in corners]
        self.features.append({"type": "Feature", "id": lot_id, "properties": props,
                              "geometry": {"type": "Polygon", "coordinates": [ring + [ring[0]]]}})

    def building(self, lot_id: str, name: str, side: str, edge: float, centre: float) -> tuple:
        """Building type ``name`` on side ``side`` of a plaza whose edge on that side is at ``edge``
        (a y for "N" and "S", an x for "E" and "W"), centred at ``centre`` along it and facing it: its
        platform and stairway reach the plaza's edge. Returns its footprint (x0, y0, x1, y1)."""
        bay, depth, props = parameters(name)
        length = bay * max(props["doors"], props["back_doors"], 1)
        setback = props["platform_margin"] + 1.4 * props["platform_h"]   # the stairway's run
        near, far = edge + setback, edge + setback + depth
        along = (centre - length / 2, centre + length / 2)
        if side == "N":      # north of the plaza, its front the south edge
            box, front = (along[0], near, along[1], far), "S"
        elif side == "S":
            box, front = (along[0], -far + 2 * edge, along[1], -near + 2 * edge), "N"
        elif side == "E":
            box, front = (near, along[0], far, along[1]), "W"
        else:
            box, front = (-far + 2 * edge, along[0], -near + 2 * edge, along[1]), "E"
        self.lot(lot_id, *box, front, {"group": lot_id[0], **props})
        return box

    def court(self, group: str, x0: float, y0: float, x1: float, y1: float, sides: dict,
              tag: str = "") -> None:
        """A plaza [x0, x1] x [y0, y1] and the buildings round it: ``sides`` maps "N", "E", "S", "W" to
        the types standing along that side (one is centred, two at the quarters)."""
        plaza = {"group": group, "type": "plaza", "plaza_h": 0.3}
        self.lot(f"{group}{tag}-plaza", x0, y0, x1, y1, "S", plaza)
        for side, names in sides.items():
            edge = {"N": y1, "S": y0, "E": x1, "W": x0}[side]
            lo, hi = (x0, x1) if side in "NS" else (y0, y1)
            slots = [(lo + hi) / 2] if len(names) == 1 else [lo + (hi - lo) / 4, lo + 3 * (hi - lo) / 4]
            for k, (name, centre) in enumerate(zip(names, slots)):
                self.building(f"{group}{tag}-{side}{k + 1}", name, side, edge, centre)


def site() -> list[dict]:
    """The eight groups. Coordinates in metres, x east and y north, the south court of group A at the
    origin."""
    s = Site()
    # A: residential, the palace in its centre between a south and a north court; its back doors open
    # on the north court, whose south side it closes.
    s.court("A", -20, -13, 20, 13, {"N": ["palace"], "E": ["plain-range-3"], "W": ["colonette-range-3"],
                                     "S": ["double-range"]}, tag="s")
    _, depth, palace = parameters("palace")
    palace_back = 13 + palace["platform_margin"] + 1.4 * palace["platform_h"] + depth
    s.court("A", -16, palace_back + 3.0, 16, palace_back + 23.0,
            {"N": ["vented-range"], "E": ["plain-range-2"], "W": ["plain-room"]}, tag="n")
    # B: the ceremonial centre, east of A: the largest plaza, the shrine on its high platform to the north.
    s.court("B", 41, -12, 91, 24, {"N": ["shrine", "door-masks"], "E": ["lattice-range"],
                                    "S": ["corner-masks", "ornate"], "W": ["fret-range"]})
    # C and D: residential quadrangles south-west and south-east of A.
    s.court("C", -52, -60, -24, -38, {"N": ["colonette-range-5"], "E": ["colonette-room"],
                                      "S": ["columned-door"], "W": ["plain-range-2"]})
    s.court("D", 20, -66, 56, -40, {"N": ["mosaic-range"], "E": ["binder-range"], "S": ["plain-range-3"],
                                    "W": ["colonette-room"]})
    # E-H: smaller groups of two or three buildings round a patio.
    s.court("E", -50, 22, -30, 40, {"N": ["fret-range"], "W": ["plain-room"], "S": ["vented-range"]})
    s.court("F", -12, -60, 8, -44, {"N": ["binder-range"], "S": ["plain-room"]})
    s.court("G", 76, -58, 98, -40, {"N": ["corner-masks"], "W": ["colonette-room"], "S": ["plain-range-2"]})
    s.court("H", 60, 45, 82, 63, {"W": ["lattice-range"], "S": ["columned-door"]})
    return s.features


def lots() -> dict:
    """The lots as a GeoJSON FeatureCollection (what main writes; tests compare)."""
    return {"type": "FeatureCollection", "features": site()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "lots.geojson")
    args = parser.parse_args()
    collection = lots()
    args.out.write_text(json.dumps(collection, separators=(",", ":")) + "\n")
    types = {f["properties"]["type"] for f in collection["features"]} - {"plaza"}
    buildings = sum(f["properties"]["type"] != "plaza" for f in collection["features"])
    print(f"{args.out}: {len(collection['features'])} lots, {buildings} buildings of {len(types)} types")


if __name__ == "__main__":
    main()
