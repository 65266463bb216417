"""Scene files and the loader: every shipped scene loads with the values its name
and the paper state; bad files fail with the file and the key in the message."""
from __future__ import annotations

import math
import re

import pytest

from trilith_xval.analytic import equations as eq
from trilith_xval.compare.cli.main import main
from trilith_xval.scenes import SCENE_DIR, load_scene, scene_names

FIG8 = [f"fig8_lam{lam}_gamma{gamma}" for lam in (3, 5, 7) for gamma in (0.1, 0.2, 0.3)]
FIG9 = [f"fig9_lam{lam}_b{b}" for lam in (3, 5, 7) for b in (0.2, 0.4, 0.6, 0.8)]
FIG11 = [f"fig11_mu{mu}" for mu in ("0.5", "1", "2", "4")]
EXPECTED = {"fig5", "single_block", "no_pendulum", *FIG8, *FIG9, *FIG11}


def test_expected_scenes_are_shipped():
    assert EXPECTED <= set(scene_names())


@pytest.mark.parametrize("name", scene_names())
def test_every_shipped_scene_loads(name):
    scene = load_scene(name)
    assert scene.name == name
    # Every shipped file starts with a comment saying where its numbers come from.
    assert (SCENE_DIR / f"{name}.toml").read_text().startswith("#")


def test_fig5_values_match_the_paper_caption():
    # Fig. 5 caption: lam = 5, B = 0.6 (m), gamma = 0.3, mu = 1; l = 2h/3 (Sec. 5.1).
    s = load_scene("fig5")
    assert (s.b, s.lam, s.gamma, s.mu) == (0.6, 5.0, 0.3, 1.0)
    assert s.pendulum_length == pytest.approx(2.0 * s.h / 3.0, rel=1e-15)  # float rounding only


@pytest.mark.parametrize("name", FIG8)
def test_fig8_grid(name):
    lam, gamma = re.fullmatch(r"fig8_lam(\d)_gamma([\d.]+)", name).groups()
    s = load_scene(name)
    assert (s.b, s.mu, s.lam, s.gamma) == (0.6, 1.0, float(lam), float(gamma))


@pytest.mark.parametrize("name", FIG9)
def test_fig9_grid(name):
    lam, b = re.fullmatch(r"fig9_lam(\d)_b([\d.]+)", name).groups()
    s = load_scene(name)
    assert (s.gamma, s.mu, s.lam, s.b) == (0.3, 1.0, float(lam), float(b))


@pytest.mark.parametrize("name", FIG11)
def test_fig11_grid(name):
    mu = re.fullmatch(r"fig11_mu([\d.]+)", name).group(1)
    s = load_scene(name)
    assert (s.lam, s.b, s.gamma, s.mu) == (5.0, 0.6, 0.3, float(mu))


def test_no_pendulum_is_fig5_without_pendulum():
    assert load_scene("no_pendulum") == load_scene("fig5").without_pendulum().replace(
        name="no_pendulum")


def test_single_block_rocks_like_housner_block():
    """With mu = 0 and gamma = 0 the frame equation is a single Housner block's:
    theta_ddot = -(3g/4R) sin(alpha - theta) (uniform rectangle, Housner 1963),
    restitution 1 - 1.5 sin^2(alpha), uplift at g/lam."""
    s = load_scene("single_block")
    assert (s.mu, s.gamma) == (0.0, 0.0)
    b, h, mu, gamma, j, l, g = s.model_args()
    p2 = 3.0 * g / (4.0 * s.R)
    for theta in (0.0, 0.05, 0.15):
        acc, _ = eq.rocking_accelerations(theta, 0.3, 0.0, 0.0, 0.0, 1.0, b, h, mu, gamma, j, l, g)
        # Same closed form, different algebra: agreement to float rounding.
        assert acc == pytest.approx(-p2 * math.sin(s.alpha - theta), rel=1e-12)
    assert eq.restitution_ratio(0.0, -1.0, b, h, mu, gamma, j) == pytest.approx(
        1.0 - 1.5 * math.sin(s.alpha) ** 2, rel=1e-12)  # closed form, float rounding
    assert eq.uplift_acceleration(0.0, 0.0, 1.0, b, h, mu, gamma, l, g) == pytest.approx(
        g / s.lam, rel=1e-12)  # Eq. 11, float rounding


def test_load_by_path_and_overrides(tmp_path):
    path = tmp_path / "mine.toml"
    path.write_text("[scene]\nb = 0.4\nlam = 3\n")
    s = load_scene(path, gamma=0.0)
    assert (s.name, s.b, s.lam, s.gamma) == ("mine", 0.4, 3.0, 0.0)
    assert load_scene(str(path)).b == 0.4


@pytest.mark.parametrize("body, key", [
    ("[scene]\nb = 0.6\nwidth = 2\n", "width"),  # unknown key
    ("[scene]\nb = true\n", "b"),  # bool would pass float() silently
    ("[scene]\nmu = \"heavy\"\n", "mu"),  # string
    ("[scene]\nlam = 0.5\n", "lam"),  # out of range
    ("[scene]\ngamma = -1\n", "gamma"),  # out of range
    ("[scene]\nb = [1, 2]\n", "b"),  # not a scalar
    ("[scene]\nname = 3\n", "name"),
])
def test_bad_files_name_the_file_and_the_key(tmp_path, body, key):
    path = tmp_path / "bad.toml"
    path.write_text(body)
    with pytest.raises(ValueError) as info:
        load_scene(path)
    message = str(info.value)
    assert str(path) in message and key in message


@pytest.mark.parametrize("body", ["b = 0.6\n", "[scene]\nb = 0.6\n[extra]\nx = 1\n",
                                  "[scene\nb = 0.6\n"])
def test_bad_structure_names_the_file(tmp_path, body):
    path = tmp_path / "bad.toml"
    path.write_text(body)
    with pytest.raises(ValueError, match=re.escape(str(path))):
        load_scene(path)


def test_unknown_scene_and_missing_file():
    with pytest.raises(ValueError, match="unknown scene 'nope'.*fig5"):
        load_scene("nope")
    with pytest.raises(ValueError, match="does not exist"):
        load_scene("/nonexistent/x.toml")
    with pytest.raises(ValueError, match="override.*'width'"):
        load_scene("fig5", width=1.0)


def test_cli_reports_bad_scene_file_with_exit_code_2(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text("[scene]\nb = 0.6\nwidht = 2\n")
    rc = main(["record", "--scene", str(path), "--out", str(tmp_path / "x.gif")])
    err = capsys.readouterr().err
    assert rc == 2
    assert err.startswith("error: ") and str(path) in err and "'widht'" in err
    assert len(err.strip().splitlines()) == 1  # one line, no traceback
    assert not (tmp_path / "x.gif").exists()


def test_a_file_may_give_h_instead_of_lam(tmp_path):
    path = tmp_path / "tall.toml"
    path.write_text("[scene]\nb = 0.5\nh = 3.5\n")
    s = load_scene(path)
    assert s.h == pytest.approx(3.5, rel=1e-15)  # h / b * b: float rounding only
    assert s.lam == pytest.approx(7.0, rel=1e-15)
    # Without b the default width is used, as for every other missing key.
    path.write_text("[scene]\nh = 1.2\n")
    assert load_scene(path).h == pytest.approx(1.2, rel=1e-15)


def test_h_and_lam_together_are_refused_in_one_line(tmp_path, capsys):
    path = tmp_path / "both.toml"
    path.write_text("[scene]\nb = 0.6\nlam = 5\nh = 3\n")
    with pytest.raises(ValueError, match=r"either lam or h.*not both"):
        load_scene(path)
    rc = main(["scenes", "--scene", str(path)])
    err = capsys.readouterr().err
    assert rc == 2 and err.startswith("error: ") and len(err.strip().splitlines()) == 1
    assert str(path) in err and "lam" in err and "h" in err


@pytest.mark.parametrize("body, words", [
    ("[scene]\nb = 0.6\nh = 0.3\n", ["h = 0.3 m", "lam must be in"]),  # lam = 0.5 < 1
    ("[scene]\nb = 0\nh = 3\n", ["b must be in"]),
    ("[scene]\nh = true\n", ["'h'", "number"]),
])
def test_bad_h_is_named(tmp_path, body, words):
    path = tmp_path / "bad.toml"
    path.write_text(body)
    with pytest.raises(ValueError) as info:
        load_scene(path)
    assert all(w in str(info.value) for w in words), str(info.value)
