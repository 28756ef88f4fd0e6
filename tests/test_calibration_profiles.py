"""Device profiles: validation, line parsing, and conversions that are exact inverses of
what the emulator sends (hypothesis), checked against independent references (mpmath
root finding for Steinhart-Hart, the divider's closed form, a published coefficient set)."""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from designkit._validation import InputError
from designkit.calibration.conversions import Identity, Linear, Thermistor
from designkit.calibration.profiles import ROLES, list_profiles, load_profile, profile_from_dict

# ----------------------------------------------------------------- strategies
bits = st.integers(min_value=8, max_value=16)
ohms = st.floats(min_value=1e3, max_value=1e5)
side = st.sampled_from(["high", "low"])


@st.composite
def thermistors(draw):
    b = draw(bits)
    v_ref = draw(st.floats(min_value=1.0, max_value=5.0))
    v_supply = draw(st.one_of(st.none(), st.floats(min_value=v_ref, max_value=2 * v_ref)))
    common = dict(adc_bits=b, v_ref=v_ref, v_supply=v_supply, series_ohm=draw(ohms), thermistor_side=draw(side))
    if draw(st.booleans()):
        return Thermistor(beta_k=draw(st.floats(min_value=2500, max_value=5000)), r0_ohm=draw(ohms),
                          t0_c=draw(st.floats(min_value=0, max_value=50)), **common)
    # Steinhart-Hart coefficients around those of real 1k-100k NTCs
    return Thermistor(sh=(draw(st.floats(min_value=0.5e-3, max_value=1.5e-3)),
                          draw(st.floats(min_value=1.5e-4, max_value=3.0e-4)),
                          draw(st.floats(min_value=0.0, max_value=2e-7))), **common)


def _usable_counts(conv: Thermistor) -> np.ndarray:
    """Every count the divider can produce and the recorder accepts."""
    c = np.arange(1, conv.full_scale, dtype=np.float64)
    return c[~conv.raw_invalid(c)]


# ----------------------------------------------------------------- inverses
@settings(max_examples=60, deadline=None)
@given(thermistors())
def test_counts_to_temperature_to_counts_is_exact(conv):
    counts = _usable_counts(conv)
    temps = conv.to_value(counts)
    assert np.all(np.isfinite(temps))
    assert np.array_equal(conv.encode(temps), counts)


@settings(max_examples=60, deadline=None)
@given(thermistors(), st.floats(min_value=-20.0, max_value=100.0))
def test_temperature_to_raw_to_temperature_is_the_identity(conv, temp_c):
    raw = conv.to_raw(temp_c)
    if not 1 <= raw <= conv.full_scale - 1:
        return  # outside what this ADC resolves (at the rails 1 - r loses all its digits)
    assert float(conv.to_value(raw)) == pytest.approx(temp_c, abs=1e-9)


@settings(max_examples=40, deadline=None)
@given(thermistors(), st.floats(min_value=0.0, max_value=60.0))
def test_encoding_picks_the_nearest_count(conv, temp_c):
    raw = float(conv.to_raw(temp_c))
    if not 1 < raw < conv.full_scale - 1:
        return
    c = float(conv.encode(temp_c))
    assert abs(c - raw) <= 0.5 + 1e-9


@settings(max_examples=60, deadline=None)
@given(st.floats(min_value=-1e3, max_value=1e3).filter(lambda g: abs(g) > 1e-6),
       st.floats(min_value=-1e3, max_value=1e3), st.floats(min_value=-1e4, max_value=1e4))
def test_linear_round_trip(gain, offset, value):
    conv = Linear(gain=gain, offset=offset)
    assert float(conv.to_value(conv.to_raw(value))) == pytest.approx(value, rel=1e-12, abs=1e-9)


@settings(max_examples=40, deadline=None)
@given(st.integers(min_value=0, max_value=4095))
def test_linear_adc_counts_round_trip_exactly(count):
    conv = Linear(gain=0.007, offset=-0.3, adc_bits=12)
    assert float(conv.encode(conv.to_value(count))) == count
    assert not conv.raw_invalid(np.array([count]))[0]
    assert conv.raw_invalid(np.array([4096.0, -1.0, 12.5])).all()


@settings(max_examples=60, deadline=None)
@given(st.integers(min_value=0, max_value=8), st.floats(min_value=-200, max_value=200))
def test_identity_prints_within_half_a_last_digit(decimals, value):
    conv = Identity(decimals=decimals)
    printed = conv.format(conv.encode(np.array([value])))[0]
    assert abs(float(printed) - value) <= 0.5 * 10.0 ** -decimals + 1e-9


# ---------------------------------------------------------- independent refs
def test_steinhart_hart_inverse_matches_mpmath_root_finding():
    a, b, c = 1.129241e-3, 2.341077e-4, 8.775468e-8
    conv = Thermistor(adc_bits=12, v_ref=3.3, series_ohm=1e4, sh=(a, b, c))
    mpmath.mp.dps = 40
    for t in (-30.0, 0.0, 25.0, 37.5, 80.0, 150.0):
        inv_t = mpmath.mpf(1) / (mpmath.mpf(t) + mpmath.mpf("273.15"))
        root = mpmath.findroot(lambda x: a + b * x + c * x ** 3 - inv_t, 9)
        assert float(conv.log_resistance_from_c(t)) == pytest.approx(float(root), rel=1e-13)


def test_published_10k_coefficients_give_25c_at_10_kohm():
    # The widely published Steinhart-Hart set of 10 kOhm (25 degC) NTC thermistors.
    conv = Thermistor(adc_bits=12, v_ref=3.3, series_ohm=1e4, sh=(1.129241e-3, 2.341077e-4, 8.775468e-8))
    assert float(conv.c_from_log_resistance(math.log(1e4))) == pytest.approx(25.0, abs=0.01)


def test_beta_equation_at_its_reference_point_and_against_mpmath():
    conv = Thermistor(adc_bits=12, v_ref=3.3, series_ohm=1e4, beta_k=3950.0, r0_ohm=1e4, t0_c=25.0)
    assert float(conv.c_from_log_resistance(math.log(1e4))) == pytest.approx(25.0, abs=1e-10)
    r0 = mpmath.mpf(10000) * mpmath.exp(mpmath.mpf(3950) * (1 / mpmath.mpf("273.15") - 1 / mpmath.mpf("298.15")))
    assert float(conv.c_from_log_resistance(float(mpmath.log(r0)))) == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("thermistor_side", ["high", "low"])
def test_divider_reads_equal_resistors_at_half_the_supply(thermistor_side):
    # R_thermistor = R_series puts the ADC node at Vs/2 on either side.
    conv = Thermistor(adc_bits=12, v_ref=3.3, v_supply=3.3, series_ohm=1e4, thermistor_side=thermistor_side,
                      beta_k=3950.0, r0_ohm=1e4, t0_c=25.0)
    assert float(conv.to_raw(25.0)) == pytest.approx(4095 / 2, abs=1e-9)


def test_divider_direction_follows_the_side():
    kw = dict(adc_bits=12, v_ref=3.3, series_ohm=1e4, beta_k=3950.0, r0_ohm=1e4, t0_c=25.0)
    high, low = Thermistor(thermistor_side="high", **kw), Thermistor(thermistor_side="low", **kw)
    # hotter -> smaller R_t: the node rises when the thermistor is on the high side, falls on the low side
    assert float(high.to_raw(40.0)) > float(high.to_raw(25.0))
    assert float(low.to_raw(40.0)) < float(low.to_raw(25.0))


def test_rails_and_impossible_counts_are_refused():
    conv = Thermistor(adc_bits=12, v_ref=3.3, v_supply=1.65, series_ohm=1e4, beta_k=3950.0, r0_ohm=1e4, t0_c=25.0)
    bad = conv.raw_invalid(np.array([0.0, 4095.0, 3000.0, 12.5, -3.0]))
    assert bad.all()  # 3000 counts = 2.42 V > the 1.65 V supply
    assert not conv.raw_invalid(np.array([1000.0]))[0]


# ------------------------------------------------------------- shipped files
def test_shipped_profiles_load_and_describe_themselves():
    names = list_profiles()
    assert {"designkit", "adc12-thermistor"} <= set(names)
    native = load_profile("designkit")
    assert native.has_timestamp and native.has_object and native.has_force
    assert native.contact.force_threshold_n == 5.0  # the paper's threshold
    rig = load_profile("adc12-thermistor")
    assert rig.serial.baudrate == 115200 and not rig.has_timestamp
    assert isinstance(rig.channels["sensor"].conversion, Thermistor)
    assert rig.channels["sensor"].conversion.adc_bits == 12
    # to_dict is the YAML schema: it loads back to the same profile
    again = profile_from_dict(rig.to_dict())
    assert again.to_dict() == rig.to_dict()


@pytest.mark.parametrize("name", ["designkit", "adc12-thermistor"])
@settings(max_examples=30, deadline=None)
@given(sensor=st.floats(min_value=0.0, max_value=60.0), obj=st.floats(min_value=0.0, max_value=60.0),
       force=st.floats(min_value=0.0, max_value=25.0))
def test_wire_round_trip_through_parse_and_convert(name, sensor, obj, force):
    prof = load_profile(name)
    values = {"sensor": np.array([sensor]), "object": np.array([obj]), "force": np.array([force]),
              "timestamp": np.array([12.345])}
    line = prof.format_lines(values)[0].encode() + b"\n"
    parsed = prof.parse_lines([line])
    assert not parsed.errors
    out, bad = prof.convert(parsed.raw)
    assert not bad.any()
    conv = prof.channels["sensor"].conversion
    if isinstance(conv, Thermistor):  # one count either side of the true reading
        c = float(conv.encode(sensor))
        tol = abs(float(conv.to_value(c + 1)) - float(conv.to_value(c - 1)))
    else:
        tol = 0.5 * 10.0 ** -conv.decimals + 1e-12
    assert abs(out[0, ROLES.index("sensor")] - sensor) <= tol


def test_parse_lines_sorts_out_bad_lines_and_counts_slots():
    prof = load_profile("designkit")
    lines = [b"0.0000,35.0,25.0,0.0", b"# booting", b"\xff\xfe garbage", b"0.0100,35.0,25.0",
             b"0.0150,35.0,nan,0.0", b"0.0200,35.0,x,0.0", b"", b"0.0250,35.1,25.0,0.1"]
    p = prof.parse_lines(lines)
    kinds = [k for _, k, _ in p.errors]
    assert kinds == ["garbled", "field_count", "non_numeric", "non_numeric"]
    assert p.messages == ["# booting"]
    assert p.rows == [0, 7]
    # every non-empty, non-message line is one sample slot, readable or not
    assert list(p.slots) == [0, 5] and p.n_slots == 6


def test_convert_flags_out_of_range_readings():
    prof = load_profile("adc12-thermistor")
    p = prof.parse_lines([b"2000,2000,0,100", b"0,2000,0,100", b"4095,2000,0,100", b"5000,2000,0,100",
                          b"2000,2000,0,9000"])
    _, bad = prof.convert(p.raw)
    assert list(bad) == [False, True, True, True, True]


# ---------------------------------------------------------------- validation
@pytest.mark.parametrize("edit, message", [
    (lambda d: d["channels"].pop("sensor"), "channels.sensor"),
    (lambda d: d["serial"].update(baud=9600), "unknown key(s) baud in serial"),
    (lambda d: d["serial"].update(parity="maybe"), "serial.parity"),
    (lambda d: d["serial"].update(stopbits=3), "serial.stopbits"),
    (lambda d: d["contact"].update(release_n=6.0), "contact.release_n"),
    (lambda d: d["channels"]["sensor"].update(field="nope"), "channels.sensor.field"),
    (lambda d: d["line"].update(fields=["a", "a", "b"]), "duplicate"),
    (lambda d: d["channels"].pop("force"), "contact.rule force needs a channels.force"),
    (lambda d: d.pop("sample_rate_hz"), "missing key sample_rate_hz"),
    (lambda d: d["channels"]["sensor"].update(valid=[5, 1]), "channels.sensor.valid"),
    (lambda d: d["channels"]["sensor"].update(conversion={"type": "thermistor", "adc_bits": 12, "v_ref": 3.3,
                                                          "series_ohm": 1e4}), "exactly one of beta"),
    (lambda d: d["channels"]["sensor"].update(conversion={"type": "linear", "gain": 0}), "gain must not be 0"),
    (lambda d: d.update(designkit_profile=7), "unsupported profile version"),
])
def test_bad_profiles_raise_one_line_errors(edit, message):
    data = yaml.safe_load(open(list_profiles()["designkit"]).read())
    edit(data)
    with pytest.raises(InputError) as exc:
        profile_from_dict(data, source="profile test.yaml")
    text = str(exc.value)
    assert message in text and "\n" not in text and text.startswith("profile test.yaml")


def test_unknown_profile_name_and_bad_yaml(tmp_path):
    with pytest.raises(InputError, match="unknown device profile 'nope'.*designkit"):
        load_profile("nope")
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: [unclosed\n")
    with pytest.raises(InputError, match="not valid YAML"):
        load_profile(bad)


def test_profile_that_is_not_utf8_is_named(tmp_path):
    shipped = list_profiles()["designkit"].read_bytes()
    bad = tmp_path / "latin1.yaml"
    bad.write_bytes(shipped.replace(b"\n", b"\n# caf\xe9\n", 1))  # a comment saved as Latin-1
    with pytest.raises(InputError) as exc:
        load_profile(bad)
    assert str(exc.value) == f"profile {bad} is not UTF-8 text (byte 0xe9 on line 2)"
    bom = tmp_path / "bom.yaml"
    bom.write_bytes(b"\xef\xbb\xbf" + shipped)
    assert load_profile(bom).name == load_profile("designkit").name
