"""The arguments of how lots are read, which several commands share: made on a command's parser
(``add_lots_options``), read back into ``io.lot_format.LotsOptions`` (``lots_options``)."""

from __future__ import annotations


def add_lots_options(command) -> None:
    """The arguments of how lots are read: ``--crs``, ``--lots-crs``, ``--id-field``, ``--min-area``."""
    command.add_argument("--crs", metavar="CRS",
                         help="metric coordinate system to reproject lots in longitude/latitude to (e.g. "
                              "EPSG:2056; default: the UTM zone of their centre)")
    command.add_argument("--lots-crs", metavar="CRS",
                         help="coordinate system of the lots' file where it names none or the wrong one "
                              "(e.g. EPSG:4326)")
    command.add_argument("--id-field", metavar="NAME",
                         help="the lots' property that holds their ids (e.g. osm_id; default: a feature's id, "
                              "else its `id` or `name` property, else its number)")
    command.add_argument("--min-area", type=float, metavar="M2",
                         help="lots of less area (square metres) are bad: slivers")


def lots_options(args):
    """The ``io.lot_format.LotsOptions`` of ``--lots-crs``, ``--crs``, ``--id-field`` and ``--min-area``;
    None without any."""
    from grammarc.io.lot_format import NO_OPTIONS, LotsOptions

    options = LotsOptions(lots_crs=args.lots_crs, crs=args.crs, id_field=args.id_field, min_area=args.min_area)
    return options if options != NO_OPTIONS else None
