"""Typed solver settings, built once from a validated scene: the solvers never read the scene.

Each algorithm takes one frozen settings object: its parameters from the scene's
``[solver]`` table and, as :class:`Model`, what it must know of the problem beyond the
assembled system (3.62): the material, the boundary parts, the friction law and mu_f,
the h^ choice. The defaults live only in :mod:`ngdual.scene`; a settings object has
none, so a solver never silently runs with a value nobody chose.

>>> from ngdual.scene import load_scene
>>> settings = solver_settings(load_scene("thesis-3.46-coulomb"))
>>> type(settings).__name__, settings.model.law, settings.model.mu_f
('ActiveSetSettings', 'coulomb', 0.5)
>>> uzawa_settings = NestedUzawaSettings.from_scene(load_scene("thesis-3.46-coulomb"), eps2=1e-8)
>>> uzawa_settings.eps2, uzawa_settings.rho2, uzawa_settings.condensed
(1e-08, 1.0, True)
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import ClassVar

from ..scene import Scene, SceneTypeError


@dataclass(frozen=True)
class Model:
    """What a solver must know of the problem besides the assembled system (3.62).

    Attributes
    ----------
    lame : tuple of float
        Lamé's (lambda, mu) of the compliance (material.E, material.nu, plane strain).
    plane_strain_modulus : float
        E* = E / (1 - nu^2), the scale of the H^{1/2} metric on Gamma_C.
    dirichlet, neumann, contact : tuple of str
        The labels of Gamma_D, Gamma_N and Gamma_C.
    law : {"none", "tresca", "coulomb"}
        The friction law on Gamma_C ("none" without a contact boundary).
    mu_f : float
        The Coulomb coefficient of (3.123); 0 unless ``law = "coulomb"``.
    hhat_factor : int
        h^ / h~ (1 or 2): with 1 the inf-sup condition (3.74) for nu can fail.
    """

    lame: tuple[float, float]
    plane_strain_modulus: float
    dirichlet: tuple[str, ...]
    neumann: tuple[str, ...]
    contact: tuple[str, ...]
    law: str
    mu_f: float
    hhat_factor: int

    @classmethod
    def of(cls, scene: Scene) -> Model:
        """The model of a validated ``scene``."""
        law = scene.friction.law if scene.has_friction else "none"
        return cls(lame=tuple(scene.material.lame),
                   plane_strain_modulus=scene.material.plane_strain_modulus,
                   dirichlet=tuple(scene.labels("dirichlet")),
                   neumann=tuple(scene.labels("neumann")),
                   contact=tuple(scene.labels("contact")),
                   law=law, mu_f=float(scene.friction.mu) if law == "coulomb" else 0.0,
                   hhat_factor=scene.contact.hhat_factor)

    def labels(self, role: str) -> list[str]:
        """The labels of a boundary role ("dirichlet", "neumann", "contact")."""
        return list(getattr(self, role))

    @property
    def has_contact(self) -> bool:
        return bool(self.contact)

    @property
    def has_friction(self) -> bool:
        return self.law != "none"


class _FromScene:
    """``from_scene``: the fields of the scene's [solver] table with the same names."""

    @classmethod
    def from_scene(cls, scene: Scene, **changes):
        """Settings of ``cls`` from ``scene`` (its model and [solver] table), then ``changes``.

        ``changes`` replace single fields, of the settings (e.g. a tighter ``eps2`` for a
        comparison) or of the model (e.g. another ``mu_f`` on the same assembled problem).
        ``solver.condensed = "auto"`` becomes the choice :data:`CONDENSED_AUTO` makes for
        ``cls``.
        """
        model_fields = {f.name for f in dataclasses.fields(Model)}
        model = dataclasses.replace(Model.of(scene), **{k: v for k, v in changes.items()
                                                        if k in model_fields})
        values = {f.name: getattr(scene.solver, f.name) for f in dataclasses.fields(cls)
                  if f.name != "model"}
        if values.get("condensed") == "auto":
            values["condensed"] = CONDENSED_AUTO[cls.method]
        return dataclasses.replace(cls(model=model, **values),
                                   **{k: v for k, v in changes.items() if k not in model_fields})


# solver.condensed = "auto" (the scene's default): the Gamma_C response costs 2 N_C + 1
# solves once and pays off after about as many steps. Nested Uzawa takes thousands of
# inner steps; Algorithm 3.38 in the H^{1/2} metric takes tens, independent of h, so the
# response costs more than it saves from level 5 of Example 3.46 on (N_C = 63, 17 steps:
# 25 s against 7.5 s for the sparse solves).
CONDENSED_AUTO = {"uzawa": False, "nested-uzawa": True}


def _check_condensed(settings) -> None:
    """A settings object's ``condensed`` is True or False (a scene's "auto" is resolved by
    :meth:`_FromScene.from_scene`)."""
    if not isinstance(settings.condensed, bool):
        raise SceneTypeError("solver.condensed", f"must be True or False, got "
                                                 f"{settings.condensed!r}")


@dataclass(frozen=True)
class LinearSettings(_FromScene):
    """One saddle-point solve (no contact boundary, ``solver.method = "uzawa"``)."""

    method: ClassVar[str] = "linear"
    model: Model


@dataclass(frozen=True)
class UzawaSettings(_FromScene):
    """Algorithm 3.38 (frictionless contact): ``solver.rho``, ``eps``, ``max_iter``, ``metric``,
    ``condensed``.

    ``rho`` is the dimensionless step (the metric carries E*), ``eps`` the tolerance on the
    relative increment of step 5, ``metric`` that of the projection P^+ ("h12" or
    "euclidean", :mod:`ngdual.solvers.projections`), ``condensed`` whether the steps run on
    the Gamma_C response (:class:`~ngdual.solvers.uzawa.ContactLoop`).
    """

    method: ClassVar[str] = "uzawa"
    model: Model
    rho: float
    eps: float
    max_iter: int
    metric: str
    condensed: bool

    def __post_init__(self):
        _check_condensed(self)


@dataclass(frozen=True)
class NestedUzawaSettings(_FromScene):
    """Algorithm 3.41 / Remark 3.45 (Tresca / Coulomb friction).

    ``rho1``, ``eps1``: step and tolerance of the contact loop (lambda_n); ``rho2`` in
    (0, 2): step of the nu update relative to its stability bound; ``eps2``: tolerance of
    the outer increments; ``loop_order``: "friction-outer" (Algorithm 3.41) or
    "contact-outer" (Remark 3.43); ``friction_metric``: "jacobi" or "mass" (Remark 3.44);
    ``condensed``: whether the loops run on the Gamma_C response.
    """

    method: ClassVar[str] = "nested-uzawa"
    model: Model
    rho1: float
    rho2: float
    eps1: float
    eps2: float
    max_iter: int
    metric: str
    loop_order: str
    friction_metric: str
    condensed: bool

    def __post_init__(self):
        _check_condensed(self)


@dataclass(frozen=True)
class ActiveSetSettings(_FromScene):
    """The active-set solver on Gamma_C (:mod:`ngdual.solvers.active_set`).

    It iterates to round-off and needs no tolerance: ``max_iter`` bounds the Coulomb
    fixed-point steps, ``metric`` is that of the reported natural contact residual.
    """

    method: ClassVar[str] = "active-set"
    model: Model
    max_iter: int
    metric: str


Settings = LinearSettings | UzawaSettings | NestedUzawaSettings | ActiveSetSettings


def solver_settings(scene: Scene) -> Settings:
    """The settings of the algorithm ``scene`` calls for (``solver.method``, its contact and law).

    ``"auto"`` and ``"active-set"``: :class:`ActiveSetSettings`; ``"uzawa"``: the linear
    solve without contact, Algorithm 3.38 without friction, Algorithm 3.41 with it.
    """
    if scene.solver.method in ("auto", "active-set"):
        return ActiveSetSettings.from_scene(scene)
    if not scene.has_contact:
        return LinearSettings.from_scene(scene)
    if not scene.has_friction:
        return UzawaSettings.from_scene(scene)
    return NestedUzawaSettings.from_scene(scene)
