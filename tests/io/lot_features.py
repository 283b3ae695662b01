"""Features of every kind a lots file holds: a polygon with street widths, a line, a MultiPolygon with a
hole, and bad street widths (shared by the GeoParquet and partition tests)."""

FEATURES = [
    {"type": "Feature", "id": "a", "properties": {"kind": "house", "h": 12, "streetWidth": [8, 0, 0, 0]},
     "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [20, 0], [20, 15], [0, 15], [0, 0]]]}},
    {"type": "Feature", "id": "line", "properties": {"kind": "x", "h": None},
     "geometry": {"type": "LineString", "coordinates": [[0, 0], [5, 5]]}},
    {"type": "Feature", "id": "m", "properties": {"kind": "court", "h": 7.5},
     "geometry": {"type": "MultiPolygon", "coordinates": [
         [[[40, 0], [80, 0], [80, 40], [40, 40], [40, 0]], [[50, 10], [50, 30], [70, 30], [70, 10], [50, 10]]],
         [[[100, 0], [110, 0], [110, 10], [100, 0]]]]}},
    {"type": "Feature", "id": "bad-width", "properties": {"kind": "house", "h": 3, "streetWidth": [1, 2]},
     "geometry": {"type": "Polygon", "coordinates": [[[0, 30], [10, 30], [10, 40], [0, 40], [0, 30]]]}},
]
