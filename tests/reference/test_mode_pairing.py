"""Pairing the modes of two models by shape (tmfem.reference.mode_pairing,
tmfem.reference.shared_shapes, the pairs of tmfem.reference.model_compare).

References: closed forms of the MAC (cos^2 of the angle between two vectors; 1 for a span
against itself whatever its basis), the M-orthonormality of a model's own modes (their MAC in
the mass-weighted vector is the identity), and, for the user system with slender bars, the
SBC beams' share of the strain energy (an independent quantity: the beam element's own
tangent) and the same system with stiff bars.
"""
import csv
import json
from pathlib import Path

import numpy as np
import pytest

from tmfem.cli import main
from tmfem.reference import mode_pairing
from tmfem.reference.mode_pairing import cluster_mac, frequency_clusters, mac_matrix, pair_modes

SYSTEMS = Path(__file__).resolve().parents[1] / "data" / "systems"
SLENDER = SYSTEMS / "slender-triangle-1-3.toml"


def test_mac_is_the_squared_cosine_of_the_angle():
    a = np.array([[1.0], [0.0], [0.0]])
    alpha = np.radians([0.0, 30.0, 90.0])
    B = np.vstack([np.cos(alpha), np.sin(alpha), np.zeros(3)])
    assert mac_matrix(a, B)[0] == pytest.approx(np.cos(alpha) ** 2, abs=1e-15)
    assert mac_matrix(a, -3.0 * a)[0, 0] == pytest.approx(1.0)          # scale and sign do not matter


def test_a_model_s_own_modes_have_mac_one_with_themselves_and_zero_with_each_other_mass_weighted():
    """The MTC model's modes are M-orthonormal (phi_i^T M phi_j = delta_ij): in the vector
    M^(1/2) phi their MAC matrix is the identity; plain (unweighted) it has ones on the
    diagonal and small entries elsewhere."""
    from tmfem.models.mtc.model import MTCModel
    from tmfem.system import load_preset
    m = MTCModel(load_preset("1-4"), mesh_n=4)
    md = m.modes(k=8, at=m.equilibrium())
    M = m.mass().toarray()
    w, V = np.linalg.eigh(M)
    half = V @ np.diag(np.sqrt(np.clip(w, 0.0, None))) @ V.T
    assert mac_matrix(half @ md.shapes, half @ md.shapes) == pytest.approx(np.eye(8), abs=1e-8)
    plain = mac_matrix(md.shapes, md.shapes)
    assert np.diag(plain) == pytest.approx(1.0)
    assert np.max(plain - np.diag(np.diag(plain))) < 0.2


def test_a_repeated_pair_is_compared_by_its_span_whatever_its_basis():
    """Two bases of one plane (a degenerate pair taken differently by two models): plain MAC of
    the single vectors is cos^2 of the rotation (0.5 at 45 deg), MAC* against the other's
    cluster is 1 and the pair is paired in order; a third, orthogonal mode pairs with its own."""
    rng = np.random.default_rng(0)
    A = np.linalg.qr(rng.standard_normal((20, 3)))[0]
    c, s = np.cos(np.pi / 4), np.sin(np.pi / 4)
    B = np.column_stack([c * A[:, 0] + s * A[:, 1], -s * A[:, 0] + c * A[:, 1], A[:, 2]])
    assert mac_matrix(A[:, :2], B[:, :2]) == pytest.approx(np.full((2, 2), 0.5))
    f = [1.0, 1.0, 2.0]
    assert [list(c) for c in frequency_clusters(f)] == [[0, 1], [2]]
    score = cluster_mac(A, B, clusters=frequency_clusters(f))
    assert score == pytest.approx(np.array([[1, 1, 0], [1, 1, 0], [0, 0, 1]]), abs=1e-12)
    p = pair_modes(A, B, reference_hz=f, other_hz=f)
    assert p.partner == [0, 1, 2] and p.is_identity and p.mac == pytest.approx([1, 1, 1])


def test_a_mode_is_projected_on_the_span_of_the_other_s_cluster():
    """MAC* of a vector against a cluster is the squared norm of its projection on the span:
    (1, 1, 1)/sqrt(3) against the plane (e1, e2) gives 2/3 for both modes of the plane; close
    but distinct frequencies (0.5 % apart) are not one cluster."""
    a = np.array([[1.0], [1.0], [1.0]])
    B = np.eye(3)[:, :2]
    assert cluster_mac(a, B, clusters=frequency_clusters([2.0, 2.0]))[0] == pytest.approx([2 / 3, 2 / 3])
    assert [list(c) for c in frequency_clusters([2.0, 2.01])] == [[0], [1]]
    assert cluster_mac(a, B, clusters=frequency_clusters([2.0, 2.01]))[0] == pytest.approx([1 / 3, 1 / 3])


def test_a_mode_without_counterpart_is_left_unpaired_and_the_rest_pair_across_the_gap():
    """Reference modes e1, e2, e3 against other modes e1, e3: e2 has MAC 0 with both (below
    the threshold), e3 pairs with the other's second mode."""
    A = np.eye(4)[:, :3]
    B = np.eye(4)[:, [0, 2]]
    p = pair_modes(A, B, reference_hz=[1.0, 2.0, 3.0], other_hz=[1.0, 3.0])
    assert p.partner == [0, None, 1] and p.unpaired == [1] and p.unpaired_other == []
    assert p.mac[1] < mode_pairing.MAC_THRESHOLD


def _compare(argv, capsys):
    assert main(argv + ["--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_slender_bars_bending_modes_have_no_counterpart_and_the_membrane_modes_pair_across_them(tmp_path, capsys):
    """The 1-3 test system with 6 mm bars (slender-triangle-1-3.toml, mesh 6): the SBC model's
    modes 6-10 (3.5-3.9 Hz) bend the bars -- more than half of their strain energy is in the
    beams -- and have no counterpart in the MTC and COM models (straight, rigid bars); SBC
    modes 11-12 (4.26 Hz) pair with MTC and COM modes 6-7 (MAC > 0.95, within 1.5 %), where the
    comparison by order sets SBC mode 6 against MTC mode 6, 20 % apart. Modes 1-5 pair in order."""
    csv_path = tmp_path / "c.csv"
    r = _compare(["compare", str(SLENDER), "--modes", "12", "--mesh", "6", "--csv", str(csv_path),
                  "--plot", str(tmp_path / "c.png")], capsys)
    assert (tmp_path / "c.png").stat().st_size > 10_000      # the paired differences, gaps at 6-10
    p = r["mode_pairs"]
    for m in ("MTC", "COM"):
        assert p[m]["mode"] == [1, 2, 3, 4, 5, None, None, None, None, None, 6, 7]
        assert min(p[m]["mac"][10:]) > 0.95 and max(p[m]["mac"][5:10]) < mode_pairing.MAC_THRESHOLD
        assert max(abs(v) for v in p[m]["vs_SBC"][10:]) < 0.015
        assert p[m]["unpaired"] == [8, 9, 10, 11, 12] and not p[m]["identity"]
    assert r["vs_SBC"]["ours"]["MTC"][5] > 0.15                          # by order: 20 % apart
    unpaired = p["SBC_unpaired"]
    assert [u["mode"] for u in unpaired] == [6, 7, 8, 9, 10]
    assert all(u["beam_energy_fraction"] > 0.5 and u["without"] == ["MTC", "COM"] for u in unpaired)
    assert r["max_abs_vs_SBC"]["paired"]["MTC"] == pytest.approx(
        max(abs(v) for v in p["MTC"]["vs_SBC"] if v is not None))
    rows = list(csv.DictReader(open(csv_path)))
    assert rows[10]["MTC_paired_mode"] == "6" and rows[5]["MTC_paired_mode"] == ""
    assert float(rows[10]["MTC_paired_vs_SBC"]) == pytest.approx(p["MTC"]["vs_SBC"][10])
    assert main(["compare", str(SLENDER), "--modes", "12", "--mesh", "6"]) == 0
    out = capsys.readouterr().out
    assert "SBC mode 6 (3.5321 Hz): no counterpart in MTC or COM" in out and "the bars bend" in out
    assert "MTC modes [8, 9, 10, 11, 12]: paired with no SBC mode" in out


def test_the_same_system_with_stiff_bars_pairs_in_order(capsys):
    """The 25 mm bars of triangle-1-3.toml move the bending modes out of the band: every one
    of the 12 lowest modes pairs in order, MAC >= 0.99 with the MTC model, >= 0.88 with the COM
    (its mode 12, 4.96 Hz: the COM's own approximation), and no SBC mode has more than 5 % of
    its strain energy in the bars (negative shares: rigid-bar modes that the compressed bars'
    geometric stiffness softens)."""
    r = _compare(["compare", str(SYSTEMS / "triangle-1-3.toml"), "--modes", "12", "--mesh", "6"], capsys)
    p = r["mode_pairs"]
    assert p["MTC"]["identity"] and min(p["MTC"]["mac"]) > 0.98
    assert p["COM"]["identity"] and min(p["COM"]["mac"]) > 0.85
    assert p["SBC_unpaired"] == [] and max(p["SBC_beam_energy_fraction"]) < 0.05


@pytest.mark.slow
def test_a_preset_whose_pairing_is_not_the_identity_keeps_the_printed_comparison_by_order(capsys):
    """1-4 at mesh 4 (6 modes): the SBC model's mode 5 (2.087 Hz) is the singlet that the MTC
    and COM models have above their degenerate pair (MTC mode 7, COM mode 8; MAC >= 0.98), and
    SBC mode 6 is one of the pair. The printed Table 6.6 columns stay by order; the paired
    table follows them."""
    r = _compare(["compare", "--preset", "1-4", "--mesh", "4", "--modes", "6"], capsys)
    p = r["mode_pairs"]
    assert p["MTC"]["mode"][:5] == [1, 2, 3, 4, 7] and p["COM"]["mode"][:5] == [1, 2, 3, 4, 8]
    assert min(p["MTC"]["mac"][4], p["COM"]["mac"][4]) > 0.95 and not p["MTC"]["identity"]
    assert p["MTC"]["mode"][5] in (5, 6) and p["COM"]["mode"][5] in (5, 6)
    assert len(r["vs_SBC"]["ours"]["MTC"]) == 6 and r["printed"] is not None
    assert main(["compare", "--preset", "1-4", "--mesh", "4", "--modes", "6"]) == 0
    out = capsys.readouterr().out
    assert "modes paired by shape (the printed table compares by order):" in out
