"""Things to build and show: link plates (DXF), vector drawings (SVG), animations.

* :mod:`~mechsyn.export.plates`: links as flat plates to cut, laid out on a sheet;
* :mod:`~mechsyn.export.dxf`: the plates as a DXF drawing (ezdxf);
* :mod:`~mechsyn.export.svg`: plates and the mechanism at a pose as SVG text;
* :mod:`~mechsyn.export.drawing`: a mechanism at a pose with its points' paths, simulated
  then drawn as SVG;
* :mod:`~mechsyn.export.movie`: frames written as GIF, MP4 or an HTML player.

The functions return text or bytes, or write whole files atomically; they sit above the
kinematics they draw from.
"""

from mechsyn.export.plates import Plate, PlateLayout, link_plates, plate_outline

__all__ = ["Plate", "PlateLayout", "link_plates", "plate_outline"]
