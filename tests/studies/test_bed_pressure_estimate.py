"""The bed's largest pressure a refinement study compares (plateqp.estimate.Quantities): the
force between plate and soil over the node's area, on every soil model. On Winkler's springs it
is k × the compression (Winkler's law); a coupled soil's settlement is no spring's compression
(Pasternak's shear carries load; the half-space has no k at all, which raised TypeError)."""

import pytest

import plateqp as pq
from plateqp.estimate import Quantities

SOILS = {"winkler": dict(k=2.0e4), "pasternak": dict(model="pasternak", k=2.0e4, shear=2.0e2),
         "halfspace": dict(model="halfspace", E=1.0e4, nu=0.3)}


def scene(soil):
    return pq.Scene(plate=pq.Plate(1.0, 1.0, 0.02, 1e7, 0.3), mesh=pq.MeshSpec(8, 8, "acm"),
                    edges={"left": "simple", "right": "simple"},
                    loads=[pq.UniformLoad(20.0), pq.PointLoad(200.0, 0.6, 0.55)],
                    foundation=pq.Foundation(**SOILS[soil]))


@pytest.mark.parametrize("soil", list(SOILS))
def test_the_bed_pressure_is_force_over_area(soil):
    res = pq.solve(scene(soil), accuracy=1e-9)
    bed = res.model.contacts.source == "bed"
    area = res.model.bed_areas()[res.model.contacts.index[bed]]
    p = Quantities.of(res).p_max
    assert p == pytest.approx((res.reactions[bed] / area).max(), rel=1e-12)
    if soil == "winkler":  # Winkler's law, independently: pressure = k × compression
        assert p == pytest.approx(2.0e4 * res.compressions[bed].max(), rel=1e-6)
    else:  # the soil's settlement is not a spring's: k × v misses the coupling
        assert soil == "halfspace" or abs(p - 2.0e4 * res.compressions[bed].max()) > 0.05 * p
