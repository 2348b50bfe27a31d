"""The plants of a deployment as data (tmfem.reference.deployment_plants.FEPlantOptions): the
tendon law of each plant, the law the controller drives, and the JSON of a run."""
from tmfem.cli import build_parser
from tmfem.reference.deployment_plants import FEPlantOptions, diverged


def test_tendon_laws_of_the_plants():
    # the COM's fixed rates of eq. 5.19, the SBC model's cable law k = EA / r (its only law),
    # the MTC model's choice (cable by default)
    o = FEPlantOptions(plant="mtc", compare_plant="sbc")
    assert [o.tendons(p) for p in ("com", "sbc", "mtc")] == ["fixed-rate", "cable", "cable"]
    assert FEPlantOptions(plant="mtc", plant_tendons="fixed-rate").tendons("mtc") == "fixed-rate"
    # force-actuated FE tendons realise the COM's law at the measured q: the controller drives
    # fixed rates on every plant
    f = FEPlantOptions(plant="sbc", compare_plant="com", plant_actuation="force")
    assert f.controlled_tendon_law("sbc") == f.controlled_tendon_law("com") == "fixed-rate"
    assert f.fe_tendon_model() == "fixed-rate" and o.fe_tendon_model() == "cable"


def test_a_pfl_tendon_model_unlike_a_plants_law_is_reported_for_that_plant():
    o = FEPlantOptions(plant="com", compare_plant="mtc")
    (w,) = o.tendon_model_warnings("fixed-rate")
    assert "not the mtc plant's tendon law (cable)" in w
    assert o.tendon_model_warnings("cable") == ["the PFL's tendon model (cable) is not the com plant's tendon "
                                                "law (fixed-rate): the run on the com plant has this model "
                                                "error too"]


def test_options_of_a_parsed_command_line_and_their_json():
    args = build_parser().parse_args(["deploy", "--preset", "1-4D", "--plant", "sbc", "--plant-damping", "1e-3"])
    o = FEPlantOptions.of(args)
    assert o == FEPlantOptions(plant="sbc", plant_damping=1e-3)
    assert o.summary("com", None) == {"plant_tendons": "fixed-rate"}
    assert o.summary("sbc", 4) == {"plant_mesh": 4, "plant_tendons": "cable", "plant_bars": "rigid",
                                   "plant_damping_s": 1e-3, "plant_damping_tangent": "current",
                                   "plant_actuation": "rest-length"}
    assert o.arguments("sbc") == {"tendon_law": None, "bars": "rigid", "beta": 1e-3,
                                  "actuation": "rest-length", "damping_tangent": None}
    assert o.arguments("com") == {"tendon_law": None, "bars": None, "beta": 0.0, "actuation": "rest-length",
                                  "damping_tangent": None}


def test_a_diverged_run_is_a_failed_check():
    runs = [("com", {"t_end_s": 20.0}), ("sbc", {"t_end_s": 3.25, "failure": "diverged"})]
    assert diverged(runs) == ["closed loop on the sbc plant diverged at t = 3.25 s"]


def test_the_pfl_of_a_run_with_an_fe_plant():
    # with an FE plant in the run (either plant of a comparison) the PFL evaluates its terms at
    # the reference and models the FE plant's tendons, except under eq. 5.72 (uncertainty
    # "initial": F_q frozen with the fixed rates of eq. 5.19); on the COM alone, eq. 5.58 as is
    com, fe = FEPlantOptions(plant="com"), FEPlantOptions(plant="com", compare_plant="mtc")
    assert (com.pfl_evaluation(), fe.pfl_evaluation(), fe.pfl_evaluation("state")) == ("state", "reference", "state")
    assert com.pfl_tendon_model("no-MG") == "fixed-rate" and fe.pfl_tendon_model("no-MG") == "cable"
    assert fe.pfl_tendon_model("initial") == "fixed-rate"
