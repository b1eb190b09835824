"""Things to build and show: link plates (DXF) and vector drawings (SVG)."""

from mechsyn.export.plates import Plate, PlateLayout, link_plates, plate_outline

__all__ = ["Plate", "PlateLayout", "link_plates", "plate_outline"]
