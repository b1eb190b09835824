"""The mechanism file format (YAML or JSON, one schema), as pydantic models.

``mechsyn schema`` prints :func:`json_schema`. Example::

    name: Four-bar linkage
    kind: planar            # planar | spatial
    ground: frame           # the frame link
    links: [frame, crank, coupler, rocker]
    joints:
      - {id: A, type: R, links: [frame, crank], point: [0, 0], actuated: true}
      - {id: B, type: R, links: [crank, coupler], point: [1, 2]}
      - {id: C, type: R, links: [coupler, rocker], point: [4, 3]}
      - {id: D, type: R, links: [rocker, frame], point: [5, 0]}

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
.. [2] "Rational structural synthesis of schemes of crank-slider mechanisms of gripping
   devices" (in Ukrainian, with an English abstract) ("paper 002"; see docs/references.md).
.. [3] O. D. Egorov and M. A. Buynov, "Structural analysis of the mechanisms of the
   mechatronic and robotic devices" (in Russian), *Mekhatronika, Avtomatizatsiya,
   Upravlenie*, 17(4), 239-244, 2016. doi:10.17587/mau.17.239-244 ("paper 003").
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict, Field, field_validator
from pydantic_core import PydanticCustomError

LinkRef = str | int


def _not_bool(v: Any) -> Any:
    # YAML's true/false would otherwise be read as 1.0/0.0
    if isinstance(v, bool):
        raise PydanticCustomError("bool_not_number", "true/false is not a number")
    return v


def _finite(v: float) -> float:
    if not math.isfinite(v):
        raise PydanticCustomError("finite_number", "must be a finite number, not {value}", {"value": v})
    return v


#: A finite real number of a file; booleans are refused (not read as 1 and 0).
Number = Annotated[float, BeforeValidator(_not_bool), AfterValidator(_finite)]


# defer_build: the validators are built on first validation, not on import (a plain file
# needs none: mechsyn.io.plain)
class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", populate_by_name=True, defer_build=True)


class LinkEntry(BaseModel):
    """A link given as an object: a name (or an integer id) and extra attributes."""

    model_config = ConfigDict(extra="allow", defer_build=True)

    name: str | None = Field(None, description="Link name; defaults to the id as text.")
    id: int | None = Field(None, description="Integer id that joints may use instead of the name.")
    mass: Number | None = Field(None, ge=0, description="Mass (for force analysis).")
    com: list[Number] | None = Field(None, description="Centre of mass in the assembled configuration.")
    inertia: Number | None = Field(None, ge=0, description="Moment of inertia about the centre of mass.")
    description: str | None = None


class CamProfile(_Strict):
    """A cam profile about a centre: a disc (``radius``) or a polar function ``polar`` of
    the angle ``t`` (radians, from the x axis of the assembled configuration), e.g.
    ``"1 + 0.2*sin(t)**2"``: the profile points are ``center + r(t) (cos t, sin t)``."""

    center: list[Number]
    radius: Number | None = Field(None, gt=0, description="Radius of a disc (eccentric) cam.")
    polar: str | None = Field(None, description="r(t): +, -, *, /, **, sin, cos, tan, exp, sqrt, abs, pi, t.")


class LoadEntry(_Strict):
    """An external load on a link (force analysis): a force at a point and/or a moment."""

    link: LinkRef = Field(description="The link the load acts on.")
    force: list[Number] | None = Field(None, description="Force [Fx, Fy] (global directions).")
    at: list[Number] | None = Field(
        None, description="Point of application in the assembled configuration (default: the centre of mass, "
                          "else the link's first joint).")
    point: str | None = Field(None, description="A named point (from `points`) as point of application.")
    moment: Number | None = Field(None, description="A moment (counter-clockwise positive).")
    description: str | None = None


class JointEntry(_Strict):
    """A kinematic pair. ``links: [a, b]``: ``b`` moves relative to ``a``."""

    id: str = Field(description="Unique joint id (e.g. A, B5, D3).")
    type: str = Field(
        description=(
            "Pair type: R, P, H (with pitch), C, U (with axis2), S, E (axis = plane normal), "
            "S_pin, line_contact, point_contact, cam, gear (planar higher pairs), belt (a belt, "
            "chain, band or rope anchored on the first link wrapping a pulley on the second), generic "
            "(with class). Aliases: revolute, prismatic, spherical, cylindrical, ..."
        )
    )
    links: list[LinkRef] = Field(description="The two links the pair joins, by name or id.")
    pair_class: int | None = Field(
        None, alias="class",
        description="Class i = constraints imposed (1..5); required for generic pairs.",
    )
    point: list[Number] | None = Field(None, description="Joint (or contact / pitch) point.")
    axis: list[Number] | None = Field(
        None, description="Unit axis: rotation axis (R, H, C, U first axis), sliding direction (P), plane normal (E).",
    )
    axis2: list[Number] | None = Field(None, description="U: second axis, fixed in the second link.")
    zero: list[Number] | None = Field(
        None, description=("Spatial R, H or C pair: the direction (perpendicular to the axis, fixed on the first "
                           "link) from which its input angle is measured, to the second link's reference line "
                           "(its first joint to its first other joint). Without it the drawn pose is 0."))
    normal: list[Number] | None = Field(None, description="Higher pairs: contact normal / line of action.")
    pitch: Number | None = Field(None, description="H: lead per radian of rotation.")
    ratio: Number | None = Field(None, description="gear: angular velocity ratio of the second link to the first.")
    actuated: bool = Field(False, description="Driven joint (a drive sets its coordinate).")
    vll: Literal["active", "passive", "locked"] | None = Field(
        None, description="Variable-length link mode of a prismatic pair (paper 000).",
    )
    limits: list[Number] | None = Field(None, description="[min, max] of the joint coordinate (VLL length limits).")
    profile: "CamProfile | list[list[Number]] | None" = Field(
        None, description=(
            "cam: the profile fixed on the first link, in the assembled configuration: "
            "{center: [x, y], radius: r} (a disc, e.g. an eccentric), {center: [x, y], polar: 'r(t)'} "
            "(a function of the angle t) or a closed list of points [[x, y], ...] "
            "(interpolated by a periodic cubic spline)."),
    )
    anchor: list[Number] | None = Field(
        None, description="belt: where the flexible element is pinned on the first link (assembled configuration).")
    radius: Number | None = Field(
        None, gt=0, description="belt: pulley radius; the pulley is fixed on the second link, centred at `point`.")
    wrap: Literal["ccw", "cw"] | None = Field(
        None, description="belt: sense in which the belt turns round the pulley going from the anchor: "
                          "ccw (counter-clockwise) or cw.")
    description: str | None = None

    @field_validator("id", mode="before")
    @classmethod
    def _id_as_text(cls, v: Any) -> Any:
        return str(v) if isinstance(v, int) and not isinstance(v, bool) else v


class PointEntry(_Strict):
    """A named point fixed on a link, by its coordinates in the assembled configuration."""

    link: LinkRef
    at: list[Number]


class ExternalEntry(_Strict):
    """Paper 002's external-constraint quantities of a state."""

    W_rob: int = Field(0, ge=0, description="Working mobility with the external constraints on.")
    S_ai: int = Field(0, ge=0, description="External constraints that take the main mobility and fix the body.")
    W_a: int = Field(6, ge=0, le=6, description="Mobilities the external body loses (6 for a free body).")
    S_a: int | None = Field(None, ge=0, description="External constraints; default: sum of the added contacts' classes.")
    W_f: int | None = Field(None, description="Mobility of the mechanism isolated from the object; default: its W.")


class StateEntry(_Strict):
    """A state of a variable-structure mechanism: bodies and contacts it adds."""

    description: str | None = None
    add_links: list[str | LinkEntry] = Field(default_factory=list)
    add_joints: list[JointEntry] = Field(default_factory=list)
    contours: list[list[str]] | None = None
    external: ExternalEntry | None = None
    mobility: int | None = None


class MechanismFile(_Strict):
    """A mechanism file."""

    name: str = Field(description="Name of the mechanism.")
    kind: Literal["planar", "spatial"] = Field("planar", description="planar | spatial.")
    ground: LinkRef = Field(description="The frame link (name or id).")
    links: list[str | LinkEntry] = Field(min_length=1, description="Links, frame included.")
    joints: list[JointEntry] = Field(description="Kinematic pairs.")
    points: dict[str, PointEntry] = Field(default_factory=dict)
    contours: list[list[str]] | None = Field(
        None, description="Independent contours, each an ordered list of joint ids (paper 003's order matters).",
    )
    states: dict[str, StateEntry] = Field(default_factory=dict)
    loads: list[LoadEntry] = Field(default_factory=list, description="External loads for force analysis.")
    mobility: int | None = Field(
        None, description="Actual mobility W (idle mobilities included) when known from elsewhere.",
    )
    description: str | None = None
    source: str | None = Field(None, description="Where the mechanism comes from (paper, figure).")
    unit: Literal["mm", "cm", "m", "in"] | None = Field(
        None, description="The length unit of every coordinate (mm, cm, m or in): DXF $INSUNITS, SVG width and "
                          "height. A file without one is unitless (DXF $INSUNITS 0), never taken for metres.",
    )
    units: str | None = Field(None, description="The older spelling of unit (kept on reading; write unit).")
    colors: dict[str, str] = Field(
        default_factory=dict,
        description="Display colours by joint id or point name, as Pyslvs writes them (Green, "
                    "dark-blue, (255, 0, 0)) or any Matplotlib colour; kept by Pyslvs round trips.",
    )

    @field_validator("contours", mode="before")
    @classmethod
    def _contour_ids_as_text(cls, v: Any) -> Any:
        if isinstance(v, list):
            return [[str(x) if isinstance(x, int) else x for x in c] if isinstance(c, list) else c for c in v]
        return v


def json_schema() -> dict[str, Any]:
    """The JSON Schema of mechanism files."""
    schema = MechanismFile.model_json_schema(by_alias=True)
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "mechsyn mechanism file"
    return schema

