"""The plates of :func:`mechsyn.export.plates.link_plates` as a DXF drawing (ezdxf).

Layers: ``OUTLINE`` (closed polylines with arcs, one per plate), ``HOLES`` (circles of
    # $INSUNITS: the file's unit; a file that names none is unitless (0), never metres
    doc.units = _UNITS.get((layout.units or "").lower(), 0)
    for name, color in (("OUTLINE", 7), ("HOLES", 1), ("SLOTS", 1), ("POINTS", 3), ("LABELS", 5)):

References
----------
.. [1] Autodesk, *DXF Reference* (AutoCAD 2012), LWPOLYLINE bulge: tan(arc angle / 4).
"""

from __future__ import annotations

import io
import os

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.export.plates import PlateLayout, plate_outline
from mechsyn.results import write_atomic

__all__ = ["layout_to_dxf", "write_dxf"]

_UNITS = {"mm": 4, "cm": 5, "m": 6, "in": 1, "inch": 1, "ft": 2}


def _ezdxf():
    try:
        import ezdxf
    except ImportError:
        raise MechsynInputError("DXF export needs ezdxf (a dependency of mechsyn, missing here)", field="dxf",
                                hint='pip install "mechsyn[cad]" (or pip install ezdxf)') from None
    return ezdxf


def layout_to_dxf(layout: PlateLayout):
    """An ezdxf document of the plates (R2010 DXF)."""
    ezdxf = _ezdxf()
    doc = ezdxf.new("R2010")
    # $INSUNITS: the file's unit; a file that names none is unitless (0), never metres
    doc.units = _UNITS.get((layout.units or "").lower(), 0)
    for name, color in (("OUTLINE", 7), ("HOLES", 1), ("SLOTS", 1), ("POINTS", 3), ("LABELS", 5)):
        doc.layers.add(name, color=color)
    msp = doc.modelspace()
    for p in layout.plates:
        msp.add_lwpolyline([(x, y, 0.0, 0.0, b) for x, y, b in p.outline], format="xyseb", close=True,
                           dxfattribs={"layer": "OUTLINE"})
        for c in p.holes:
            msp.add_circle((float(c[0]), float(c[1])), layout.cut_diameter / 2, dxfattribs={"layer": "HOLES"})
        for a, b in p.slots:
            msp.add_lwpolyline([(x, y, 0.0, 0.0, bulge) for x, y, bulge in plate_outline(np.array([a, b]),
                                layout.cut_diameter / 2)], format="xyseb", close=True, dxfattribs={"layer": "SLOTS"})
        for c in p.markers:
            msp.add_circle((float(c[0]), float(c[1])), layout.cut_diameter / 6, dxfattribs={"layer": "POINTS"})
        msp.add_text(p.label, height=0.4 * layout.width,
                     dxfattribs={"layer": "LABELS", "insert": p.label_at})
    return doc


def write_dxf(layout: PlateLayout, path: str | os.PathLike[str]) -> None:
    """Write the plates as a DXF file, whole or not at all."""
    buf = io.StringIO()
    layout_to_dxf(layout).write(buf)
    write_atomic(path, buf.getvalue())
