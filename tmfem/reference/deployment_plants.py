"""The plants a deployment of 7.4 or 8.4 runs on, and the same deployment on two plants.

A deployment's controller is designed on the control-oriented model (COM); it may drive the
COM itself or an FE plant (the MTC or SBC model read through the COM-state estimate,
:func:`tmfem.control.fe_plant.state_estimate.deployment_plant`). :class:`FEPlantOptions`
holds the plants of a run and of its comparison run with the FE plant's options (tendon
law, bar measurement, damping, actuators); :func:`run_on_plant` runs a deployment set-up on
one plant and :func:`compare_plants` the same deployment on the second plant with its
deviation (docs/guides/fe-plant.md). ``tmfem deploy`` calls them with the options it parses.
"""
from __future__ import annotations

from dataclasses import dataclass

from tmfem.control.deployment.run import run_deployment
from tmfem.control.fe_plant.compare import deviation_summary, plant_deviation
from tmfem.control.fe_plant.state_estimate import DEPLOYMENT_DAMPING_TANGENT, deployment_plant
from tmfem.post.plant_compare_plot import plot_plant_comparison
from tmfem.reference.deployments import write_csv


@dataclass
class FEPlantOptions:
    """The plant of a run (``plant``: "com", "mtc" or "sbc"), the plant of its comparison run
    (``compare_plant``, or None) and the FE plant's options, None where not given:
    ``plant_tendons`` ("cable" or "fixed-rate", MTC), ``plant_bars`` ("rigid" or "chord", SBC),
    ``plant_damping`` (BETA [s] of C = BETA K), ``plant_damping_tangent`` ("current" or
    "initial") and ``plant_actuation`` ("rest-length" or "force")."""

    plant: str = "com"
    compare_plant: str | None = None
    plant_tendons: str | None = None
    plant_bars: str | None = None
    plant_damping: float | None = None
    plant_damping_tangent: str | None = None
    plant_actuation: str | None = None

    @classmethod
    def of(cls, options) -> "FEPlantOptions":
        """The options of an object with these attributes (e.g. parsed command-line options;
        a missing attribute is not given)."""
        return cls(**{k: getattr(options, k, None) for k in cls.__dataclass_fields__})

    def tendons(self, plant: str) -> str:
        """The tendon law of the plant ``plant`` of a run: the COM's fixed rates of eq. 5.19, the
        SBC model's cable law k = EA / r, the MTC model's ``plant_tendons`` (default cable)."""
        return {"com": "fixed-rate", "sbc": "cable"}.get(plant) or self.plant_tendons or "cable"

    def actuation(self) -> str:
        """The FE plants' tendon actuators: ``plant_actuation``, default rest-length."""
        return self.plant_actuation or "rest-length"

    def controlled_tendon_law(self, plant: str) -> str:
        """The tendon law the controller drives on ``plant``: a force-actuated FE plant's
        tendons follow the COM's law at the measured q (the fixed rates of eq. 5.19,
        :mod:`tmfem.control.fe_plant.tension_actuation`), otherwise :meth:`tendons`."""
        if plant != "com" and self.actuation() == "force":
            return "fixed-rate"
        return self.tendons(plant)

    def fe_tendon_model(self) -> str:
        """The adaptive PFL's tendon model with an FE plant in the run (outside eq. 5.72): the
        tendon law the controller drives on the FE plant (:meth:`controlled_tendon_law`)."""
        fe = self.plant if self.plant != "com" else self.compare_plant
        return self.controlled_tendon_law(fe)

    def tendon_model_warnings(self, tendons: str) -> list:
        """Where the adaptive PFL's tendon model ``tendons`` is not the tendon law of a plant it
        drives (the same controller on both plants of a comparison, docs/guides/fe-plant.md): one line
        each."""
        out = []
        for p in [self.plant] + ([self.compare_plant] if self.compare_plant else []):
            law = self.controlled_tendon_law(p)
            if law != tendons:
                out.append(f"the PFL's tendon model ({tendons}) is not the {p} plant's tendon law "
                           f"({law}): the run on the {p} plant has this model error too")
        return out

    def fe_in_run(self) -> bool:
        """An FE plant among the plants of the run and of its comparison run."""
        return self.plant != "com" or self.compare_plant not in (None, "com")

    def pfl_evaluation(self, given: str | None = None) -> str:
        """Where the adaptive PFL evaluates its model terms: ``given``, else at the reference
        q_d, q_d' with an FE plant in the run (the law at the state diverges there,
        docs/guides/fe-plant.md) and at the measured state (eq. 5.58) without."""
        return given or ("reference" if self.fe_in_run() else "state")

    def pfl_tendon_model(self, uncertainty: str) -> str:
        """The adaptive PFL's tendon model under the controller's model error ``uncertainty``:
        one controller drives both plants of a comparison, so with an FE plant among them the
        FE plant's tendon law (:meth:`fe_tendon_model`), except under eq. 5.72
        (``"initial"``), whose F_q is frozen with the fixed rates of eq. 5.19."""
        if self.fe_in_run() and uncertainty != "initial":
            return self.fe_tendon_model()
        return "fixed-rate"

    def damping_tangent(self) -> str:
        """The FE plant's damping tangent: ``plant_damping_tangent``, default
        :data:`tmfem.control.fe_plant.state_estimate.DEPLOYMENT_DAMPING_TANGENT`."""
        return self.plant_damping_tangent or DEPLOYMENT_DAMPING_TANGENT

    def bars(self) -> str:
        """The SBC plant's bar measurement: ``plant_bars``, default the rigid fit (the chords see
        the beams' bending modes, docs/guides/fe-plant.md)."""
        return self.plant_bars or "rigid"

    def summary(self, plant: str, mesh_n) -> dict:
        """The plant's options of a run on ``plant`` for the JSON (the COM plant: its tendon law
        only)."""
        if plant == "com":
            return {"plant_tendons": self.tendons(plant)}
        return {"plant_mesh": mesh_n, "plant_tendons": self.tendons(plant),
                **({"plant_bars": self.bars()} if plant == "sbc" else {}),
                "plant_damping_s": self.plant_damping or 0.0,
                **({"plant_damping_tangent": self.damping_tangent()} if self.plant_damping else {}),
                "plant_actuation": self.actuation()}

    def arguments(self, plant: str) -> dict:
        """The FE plant's options of a run on ``plant`` as the keyword arguments of
        :func:`tmfem.control.fe_plant.state_estimate.deployment_plant` (both deployment kinds)."""
        return {"tendon_law": self.plant_tendons if plant == "mtc" else None,
                "bars": self.bars() if plant == "sbc" else None,
                "beta": (self.plant_damping or 0.0) if plant != "com" else 0.0,
                "actuation": self.actuation() if plant != "com" else "rest-length",
                "damping_tangent": self.plant_damping_tangent if plant != "com" else None}


def diverged(runs) -> list:
    """The failed checks of (plant, result) pairs: a closed loop that diverged (``failure``)."""
    return [f"closed loop on the {p} plant diverged at t = {v['t_end_s']:.4g} s" for p, v in runs
            if v.get("failure")]


def run_on_plant(s, *, kind: str, options: FEPlantOptions, initial, mesh_n, t_end: float, dt: float,
                 progress=None):
    """The deployment of set-up ``s`` (:class:`tmfem.control.deployment.run.DeploymentSetup`)
    on the plant ``kind``: the COM itself, or an FE plant of ``options`` with membrane mesh
    ``mesh_n`` (default 10) starting in its own equilibrium of the system ``initial`` (the
    packaged configuration); ``progress(k, n)`` per step. An FE-plant run that diverges returns
    its record up to the failure (``failure``)."""
    plant = deployment_plant(kind, s.model, initial, mesh_n=mesh_n or 10, **options.arguments(kind))
    return run_deployment(model=s.model, reference=s.reference, controller=s.controller, z0=s.z0,
                          t_end=t_end, dt=dt, progress=progress, plant=plant,
                          jacobian="reuse" if plant is None else "step", partial=plant is not None)


def compare_plants(r, rerun, *, options: FEPlantOptions, preset: str, mesh_n, controller: dict, about: str,
                   reference: str = "eq. 5.68", csv: str | None = None, plot: str | None = None) -> dict:
    """The same deployment on ``options.compare_plant`` and its deviation from run ``r`` on
    ``options.plant`` (both deployment kinds): ``rerun(plant)`` runs it there with a fresh
    controller of the same options (the adaptive PFL, the switch and the LPV observer carry
    state) and returns the result and its extra JSON entries; ``controller``: those options
    (JSON of both runs), ``about``: their summary for the plot's title, ``reference``: the
    equation of the reference q_d (the plot's legend). ``csv``, ``plot``: the comparison run's
    CSV and the overlay figure (PNG) of both runs."""
    r2, extra = rerun(options.compare_plant)
    dev = plant_deviation(r, r2)
    out = {"plant": options.compare_plant, **options.summary(options.compare_plant, mesh_n),
           **controller, **r2.summary(), **extra, "deviation": deviation_summary(dev)}
    if csv:
        out["csv"] = write_csv(csv, r2)
    if plot:
        runs = [(p, options.summary(p, mesh_n)) for p in (options.plant, options.compare_plant)]
        title = (f"{preset} deployment, the same controller on both plants: "
                 f"{controller['controller']} ({about})\n" +
                 "; ".join(f"{p} plant ({ls}): " + (", ".join(
                     f"{k[6:]} {v}" for k, v in o.items() if k != "plant_damping_s" or v))
                     for (p, o), ls in zip(runs, ("solid", "dashed"))))
        out["plot"] = str(plot_plant_comparison(
            plot, r, r2, dev, labels=(options.plant, options.compare_plant), title=title,
            reference=reference))
    return out
