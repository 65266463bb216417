"""A campaign's ``pulses`` take the whole pulse family, checked at the door."""
from __future__ import annotations

import pytest

from trilith_xval.compare.campaign.study import load_study, reference_jobs


def write(tmp_path, pulses: str):
    path = tmp_path / "c.toml"
    path.write_text(f'[campaign]\nname = "c"\nscenes = ["fig5"]\nengines = ["pymunk"]\n'
                    f'pulses = {pulses}\nomega = "9:11:2"\n')
    return path


def test_the_family_is_a_study_axis(tmp_path):
    study = load_study(write(tmp_path, '["sine", "ricker", "ricker-anti", "mp"]'))
    assert study.pulses == ("sine", "ricker", "ricker-anti", "mp")
    assert {j[2] for j in reference_jobs(study)} == set(study.pulses)


def test_an_unknown_shape_is_named(tmp_path):
    with pytest.raises(ValueError, match=r"pulses: 'gauss' is not one of sine, cosine, ricker"):
        load_study(write(tmp_path, '["gauss"]'))
