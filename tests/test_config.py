"""Config errors: one test per kind of bad value; each message is one line naming the key and range."""

import pytest

import oceangnc
from oceangnc.errors import ConfigError, InputError
from oceangnc.io.config import parse_sets


def _err(**kw) -> str:
    with pytest.raises(ConfigError) as ei:
        oceangnc.resolve_config("usv-turn", **kw)
    msg = str(ei.value)
    assert "\n" not in msg
    return msg


def test_out_of_range_names_key_and_range():
    msg = _err(overrides={"environment.current.speed": 9.0})
    assert "environment.current.speed" in msg and "9.0" in msg
    assert "0 <= value <= 5" in msg and "m/s" in msg


def test_strict_lower_bound():
    msg = _err(overrides={"usv.mass": 0.0})
    assert "usv.mass" in msg and "0 < value" in msg


def test_unknown_key_nested_lists_allowed_keys():
    msg = _err(overrides={"environment.current.sped": 0.5})
    assert "unknown key 'environment.current.sped'" in msg and "speed" in msg


def test_unknown_top_level_section():
    assert "unknown key 'guidence'" in _err(overrides={"guidence.mode": "los"})


def test_wrong_type():
    msg = _err(overrides={"sim.duration": "long"})
    assert "sim.duration" in msg and "'long'" in msg


def test_bad_choice_lists_allowed_values():
    msg = _err(overrides={"environment.current.model": "random"})
    assert "allowed values" in msg and "'gauss-markov'" in msg


def test_integer_field_rejects_fraction_and_range():
    assert "environment.wind.beaufort" in _err(overrides={"environment.wind.beaufort": 13})


def test_toml_syntax_error_names_file(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("[sim\nduration = 3\n")
    assert "bad.toml" in _err(config=p)


def test_missing_file():
    assert "not found" in _err(config="/nonexistent/x.toml")


def test_set_syntax():
    with pytest.raises(ConfigError, match="key=value"):
        parse_sets(["environment.current.speed"])
    assert parse_sets(["a.b=0.5", "c=hybrid", "d=[1, 2]"]) == {"a": {"b": 0.5}, "c": "hybrid", "d": [1, 2]}


def test_unknown_scenario():
    with pytest.raises(InputError, match="known scenarios"):
        oceangnc.resolve_config("no-such-scenario")


def test_beaufort_sets_the_wind_speed():
    _, cfg = oceangnc.resolve_config("usv-turn-wind", overrides={"environment.wind.beaufort": 4})
    assert cfg.environment.wind.speed == pytest.approx((5.5 + 7.9) / 2)


def test_file_then_overrides_precedence(tmp_path):
    p = tmp_path / "c.toml"
    p.write_text('scenario = "usv-turn"\n[environment.current]\nspeed = 0.2\ndirection_deg = 10\n')
    sc, cfg = oceangnc.resolve_config(None, config=p, overrides={"environment.current.speed": 0.3})
    assert sc.name == "usv-turn"
    assert cfg.environment.current.speed == 0.3 and cfg.environment.current.direction_deg == 10
