"""A jump's kind: whether the contact grew (approach: jump-in) or shrank (retraction: jump-out), read from the
charged area where the table has it, which is the same for a state and its mirror image, while the contact length
along the apex row is not; the contact length where the table has no area."""
import math

from tengsim.results.result import Jump


def test_the_kind_reads_the_area_not_the_apex_row():
    # the landing of a symmetry-broken detachment: the area shrinks, the length along the apex row grows
    j = Jump("retraction", 15.375, 15.35, -81.7, -55.0, 26.0, 26.8, area_before=0.40, area_after=0.31)
    assert j.kind == "jump-out"
    mirror = Jump("retraction", 15.375, 15.35, -81.7, -55.0, 26.0, 25.9, area_before=0.40, area_after=0.31)
    assert mirror.kind == j.kind
    assert Jump("approach", 1.0, 1.1, -1.0, -3.0, 2.0, 1.5, area_before=0.1, area_after=0.3).kind == "jump-in"
    assert Jump("approach", 1.0, 1.1, -1.0, -3.0, 2.0, 2.5, area_before=0.3, area_after=0.1).kind == "jump"


def test_without_an_area_the_contact_length_decides():
    assert math.isnan(Jump("retraction", 2.0, 1.9, -3.0, -1.0, 2.0, 1.0).area_before)
    assert Jump("retraction", 2.0, 1.9, -3.0, -1.0, 2.0, 1.0).kind == "jump-out"
    assert Jump("retraction", 2.0, 1.9, -3.0, -1.0, 1.0, 2.0).kind == "jump"
    assert Jump("approach", 1.0, 1.1, -1.0, -3.0, 1.0, 2.0, area_before=math.nan, area_after=0.2).kind == "jump-in"
