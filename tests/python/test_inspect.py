"""``lptv inspect`` and the diagnosis ``lptv identify FILE`` runs first, on records made outside lptv.

The records (outside_records.py): a mass-spring-damper m x'' + c x' + k(t) x = f(t) with
k(t) = k0 (1 + 0.3 cos(2 pi t / T)) integrated by scipy's solve_ivp from rest (so with a start-up
transient) under a multisine NumPy builds, for periods T that are not a whole number of seconds,
with 1-3 % noise, written as a rig would (``time [s],force [N],displacement [m]``); and a
discrete-time system with a periodic coefficient run sample by sample under a periodic input
shaped by scipy.signal.lfilter. What is known by construction is checked: the period (in
samples), the excited lines, that a transient is there, that the time-varying system shows
sidebands and the time-invariant one none; and that each wrong set-up is answered with its
cause, never as a dead channel.
"""
import json

import numpy as np
import pytest

import lptv
from lptv.apps import cli
from outside_records import (discrete_lines, discrete_lptv, filtered_noise, mass_spring_damper,
                             mass_spring_damper_many, odd_lines, write_csv)

# (period s, fs Hz, periods, noise, excited lines): T fs samples a period; the second's lines are
# multiples of 3, so its input repeats every T / 3 = 140 samples and only the output every T.
CASES = {
    "odd-3": (2.5, 200.0, 8, 0.02, odd_lines(3, 20, seed=1)),
    "input-a-third": (1.75, 240.0, 8, 0.01, odd_lines(3, 20, seed=2)),
    "full": (3.2, 125.0, 6, 0.03, np.arange(1, 31)),
}
NAMES = ["--input", "force", "--output", "displacement"]
# the mass-spring-damper's structure: a2 = m, a1 = c, a0 = k(t) with one harmonic, b0 = 1
RIGHT = ["--na", "2", "--nb", "0", "--ka", "1,0,0", "--kb", "0"]


@pytest.fixture(scope="module")
def records():
    out = {}
    for name, (T, fs, P, noise, lines) in CASES.items():
        out[name] = mass_spring_damper(T, fs, P, lines=lines, noise=noise, seed=len(out) + 3)
    return out


@pytest.fixture(scope="module")
def rig(records, tmp_path_factory):
    """The first record as a rig's CSV."""
    d = tmp_path_factory.mktemp("rig")
    return write_csv(d / "rig.csv", *records["odd-3"])


def cli_run(capsys, *argv):
    rc = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return rc, out, err


# ------------------------------------------------------------------------------ what it finds

@pytest.mark.parametrize("name", list(CASES))
def test_the_period_and_the_excited_lines_of_a_simulated_rig(name, records):
    T, fs, P, noise, lines = CASES[name]
    t, f, x = records[name]
    r = lptv.inspect(u=f, y=x, fs=fs)
    N = int(round(T * fs))
    assert r.repeats and r.period_samples == N and r.period == pytest.approx(T, abs=0.5 / fs)
    assert abs(r.input_period_exact - r.input_period_samples) < 1.0           # within one sample
    if name == "input-a-third":
        assert r.input_period_samples == N // 3       # the input's own period; the output shows T
    else:
        assert r.input_period_samples == N
    assert (r.periods, r.leftover) == (P, 0)
    np.testing.assert_array_equal(r.lines, lines)
    assert r.weak_input_lines.size == 0
    assert r.transient_periods >= 1                    # the integration starts from rest
    assert f"--period {T:g}" in r.command and f"--skip-periods {r.transient_periods}" in r.command


def test_a_record_that_starts_mid_period_keeps_its_end(records):
    T, fs, P, noise, lines = CASES["odd-3"]
    t, f, x = records["odd-3"]
    cut = 137
    r = lptv.inspect(u=f[cut:], y=x[cut:], fs=fs)
    N = int(round(T * fs))
    assert r.period_samples == N and r.periods == P - 1 and r.leftover == N - cut
    np.testing.assert_array_equal(r.lines, lines)
    assert "--trim" in r.command


def test_time_variation_shows_as_sidebands_and_not_without_it():
    """The same rig with a constant stiffness (variation 0): no sideband, no detection line above
    the noise; with the 0.3 cos variation the sidebands of the excited lines stand out."""
    T, fs, P, noise, lines = CASES["odd-3"]
    t, f, x = mass_spring_damper(T, fs, P, lines=lines, noise=noise, seed=11, variation=0.0)
    lti = lptv.inspect(u=f, y=x, fs=fs, reach=1)
    assert lti.spacing == 3 and lti.reach == 1
    assert not lti.line_class("sidebands").present and lti.time_variation_reach == 0
    assert not lti.line_class("odd detection").present and not lti.line_class("even detection").present
    assert "--ka 0 --kb 0" in lti.command
    t, f, x = mass_spring_damper(T, fs, P, lines=lines, noise=noise, seed=11)
    ltv = lptv.inspect(u=f, y=x, fs=fs, reach=1)
    side = ltv.line_class("sidebands")
    assert side.present and ltv.time_variation_reach == 1 and "--ka 1 --kb 1" in ltv.command
    # a sideband is one line from an excited line
    assert all(np.min(np.abs(ltv.lines - l)) == 1 for l in side.above)
    assert "the system varies in time" in ltv.summary()


def test_a_full_multisine_says_it_cannot_show_time_variation(records):
    T, fs, P, noise, lines = CASES["full"]
    r = lptv.inspect(u=records["full"][1], y=records["full"][2], fs=fs)
    assert not r.sidebands_visible and "--ka K --kb K" in r.command
    assert "hides under them" in r.summary()


def test_a_discrete_time_record_with_a_periodic_coefficient(tmp_path):
    N, P = 300, 6
    u, y = discrete_lptv(N, P, noise=0.02, seed=4)
    r = lptv.inspect(u=u, y=y)
    assert r.fs is None and r.period is None and r.period_samples == N and r.periods == P
    np.testing.assert_array_equal(r.lines, discrete_lines(N))
    assert "--periods 6" in r.command
    # stored with fs = 40 Hz: the period is 7.5 s, not a whole number of seconds
    np.savez(tmp_path / "d.npz", u=u, y=y, fs=40.0)
    r = lptv.inspect(tmp_path / "d.npz")
    assert r.period == 7.5 and r.fs_source == "variable 'fs'" and "--period 7.5" in r.command
    # the lines left out (multiples of 7) sit next to excited ones: the design cannot tell time
    # variation from distortion there, and says so
    assert r.spacing == 1 and r.time_variation_reach >= 1
    assert "puts both on the same lines" in r.summary()


def test_a_record_that_does_not_repeat_is_said_to_and_the_one_record_route_named():
    t, u, y = filtered_noise(8000, 200.0, seed=1)
    r = lptv.inspect(u=u, y=y, fs=200.0)
    assert not r.repeats and r.command is None and r.repeat_ratio > 0.2
    s = r.summary()
    assert "does not repeat at any lag up to 20.000 s (4000 samples, half the record)" in s
    assert "--one-record --period T" in s and "lptv.identify_record" in s


def test_a_dead_input_is_refused_as_dead():
    with pytest.raises(lptv.records.channels.FileError, match="constant: a dead or disconnected input channel"):
        lptv.inspect(u=np.full(1000, 0.3), y=np.random.default_rng(0).standard_normal(1000), fs=10.0)


@pytest.mark.parametrize("scale", [1e-140, 1e-60, 1e60, 1e140])
def test_the_findings_do_not_depend_on_the_record_s_units(records, scale):
    """The same record in units 1e+-60 or 1e+-140 times larger: the same period, lines and
    transient, the spectra and noise in the record's own units (to rounding)."""
    T, fs, P, noise, lines = CASES["odd-3"]
    t, f, x = records["odd-3"]
    one = lptv.inspect(u=f, y=x, fs=fs)
    r = lptv.inspect(u=f * scale, y=x * (scale / 7.0), fs=fs)
    assert (r.period_samples, r.periods, r.transient_periods) == (one.period_samples, one.periods, one.transient_periods)
    np.testing.assert_array_equal(r.lines, one.lines)
    np.testing.assert_allclose(r.U / scale, one.U, rtol=1e-12, atol=1e-15 * np.abs(one.U).max())
    np.testing.assert_allclose(r.noise_y / (scale / 7.0) ** 2, one.noise_y, rtol=1e-10)
    assert r.command == one.command


@pytest.mark.parametrize("scale", [1e-300, 1e-200, 1e200, 1e300])
def test_a_record_whose_squares_leave_double_precision_is_refused_with_the_reason(records, scale):
    T, fs, P, noise, lines = CASES["odd-3"]
    t, f, x = records["odd-3"]
    with pytest.raises(ValueError, match=r"u reaches .*squares of its values.*rescale the record"):
        lptv.inspect(u=f * scale, y=x, fs=fs)
    with pytest.raises(ValueError, match=r"y reaches .*rescale the record"):
        lptv.inspect(u=f, y=x * scale, fs=fs)


@pytest.mark.parametrize("fs", [1e-320, 1e-150, 1e150, 1e300])
def test_a_sampling_frequency_beyond_any_units_is_refused(records, fs, tmp_path, capsys):
    t, f, x = records["odd-3"]
    with pytest.raises(ValueError, match=r"fs: a sampling frequency of .* Hz is outside"):
        lptv.inspect(u=f, y=x, fs=fs)
    with np.errstate(over="ignore"):
        dt = 1.0 / fs
    with pytest.raises(ValueError, match=r"dt: a sampling frequency of .* Hz is outside" if np.isfinite(dt)
                       else "dt must be a finite real number"):
        lptv.inspect(u=f, y=x, dt=dt)


# ------------------------------------------------------------------------------ the commands

def test_lptv_inspect_prints_the_findings_and_writes_a_report(rig, tmp_path, capsys):
    rc, out, err = cli_run(capsys, "inspect", rig, *NAMES, "--out", tmp_path / "i")
    assert rc == 0, err
    assert "input 'force [N]', output 'displacement [m]'" in out
    assert "fs = 200 Hz (from column 'time [s]', uniform)" in out
    assert "the input repeats every 2.500 s (500 samples)" in out
    suggested = next(line for line in out.splitlines() if line.startswith("suggested:"))
    assert "--input 'force [N]' --output 'displacement [m]' --period 2.5" in suggested
    s = json.loads((tmp_path / "i" / "summary.json").read_text())
    assert s["period_samples"] == 500 and s["excited_lines"] == CASES["odd-3"][4].tolist()
    page = (tmp_path / "i" / "report.html").read_text()
    assert 'alt="inspection.png"' in page and (tmp_path / "i" / "inspection.png").stat().st_size > 1000


def test_identify_names_a_wrong_period(rig, tmp_path, capsys):
    rc, out, err = cli_run(capsys, "identify", rig, *NAMES, *RIGHT, "--period", 2, "--out", tmp_path / "o")
    assert rc == 2 and out == "" and err.count("\n") == 1
    assert "the input repeats every 2.500 s (500 samples), not every 2 s" in err and "use --period 2.5" in err
    assert "dead" not in err
    # a period that does not even split the record into whole periods: the same cause, not "drop samples"
    rc, out, err = cli_run(capsys, "identify", rig, *NAMES, *RIGHT, "--period", 2.3, "--out", tmp_path / "o")
    assert rc == 2 and "not every 2.3 s" in err and "use --period 2.5" in err and "drop" not in err
    assert "--no-period-check" in err
    # asked to: the record is cut at the user's period; the fit's refusal of the output that does not
    # repeat at it comes with what the record says
    rc, out, err = cli_run(capsys, "identify", rig, *NAMES, *RIGHT, "--period", 2, "--no-period-check",
                           "--out", tmp_path / "o")
    assert rc == 2 and "the record itself says: the input repeats every 2.500 s (500 samples), not every 2 s" in err


def test_identify_names_an_fs_that_contradicts_the_time_column(rig, tmp_path, capsys):
    rc, out, err = cli_run(capsys, "identify", rig, *NAMES, *RIGHT, "--period", 2.5, "--fs", 100,
                           "--out", tmp_path / "o")
    assert rc == 2 and err.count("\n") == 1
    assert "--fs 100 contradicts the file's column 'time [s]' (200 Hz)" in err
    assert "carry signal" not in err and "dead" not in err


def test_identify_names_a_record_that_does_not_repeat(tmp_path, capsys):
    src = write_csv(tmp_path / "run.csv", *filtered_noise(8000, 200.0, seed=2))
    rc, out, err = cli_run(capsys, "identify", src, *NAMES, *RIGHT, "--period", 5, "--out", tmp_path / "o")
    assert rc == 2 and err.count("\n") == 1
    assert "the record does not repeat at any period up to 20.000 s" in err
    assert "identify it as one record" in err and "--one-record" in err and "dead" not in err


def test_identify_names_an_output_that_does_not_repeat_with_the_input(records, tmp_path, capsys):
    t, f, x = records["odd-3"]
    noise = np.random.default_rng(5).standard_normal(x.size)      # the wrong output: a sensor's noise
    src = write_csv(tmp_path / "unplugged.csv", t, f, noise)
    rc, out, err = cli_run(capsys, "identify", src, *NAMES, *RIGHT, "--period", 2.5, "--out", tmp_path / "o")
    assert rc == 2 and "the output does not repeat with the input (every 2.500 s (500 samples))" in err


def test_identify_still_calls_a_really_dead_input_dead(records, tmp_path, capsys):
    t, f, x = records["odd-3"]
    src = write_csv(tmp_path / "dead.csv", t, np.zeros_like(f), x)
    rc, out, err = cli_run(capsys, "identify", src, *NAMES, *RIGHT, "--period", 2.5, "--out", tmp_path / "o")
    assert rc == 2 and "dead or disconnected input channel" in err


def test_exit_status_0_for_a_consistent_model_and_3_for_a_rejected_one(rig, tmp_path, capsys):
    """Channel names as the user writes them (force for 'force [N]'); the right structure with the
    transient dropped is consistent (0); an LTI model of the time-varying rig is rejected (3)."""
    rc, out, err = cli_run(capsys, "identify", rig, *NAMES, *RIGHT, "--period", 2.5, "--skip-periods", 1,
                           "--lines", "excited", "--out", tmp_path / "ok")
    assert rc == 0, out + err
    assert "input 'force [N]', output 'displacement [m]'" in out.splitlines()[0]
    assert "verdict: the model is consistent with the noise" in out
    rc, out, err = cli_run(capsys, "identify", rig, *NAMES, "--na", 2, "--nb", 0, "--period", 2.5,
                           "--skip-periods", 1, "--lines", "excited", "--out", tmp_path / "lti")
    assert rc == 3 and "verdict: MODEL ERRORS" in out
    assert json.loads((tmp_path / "lti" / "summary.json").read_text())["model_ok"] is False


def test_the_wrong_count_of_periods_is_named_with_the_right_one(tmp_path, capsys):
    u, y = discrete_lptv(300, 6, noise=0.02, seed=4)
    np.savez(tmp_path / "d.npz", u=u, y=y)
    rc, out, err = cli_run(capsys, "identify", tmp_path / "d.npz", "--na", "2", "--nb", "1", "--periods", 5,
                           "--ts", 1, "--out", tmp_path / "o")
    assert rc == 2 and "the input repeats every 300 samples, not every 360 samples (--periods 5)" in err
    assert "use --periods 6" in err


def test_the_transient_advice_leaves_no_bias_and_identify_says_when_one_is_left(tmp_path, capsys):
    """A rig from rest whose transient decays as exp(-0.27 t) (c = 0.54, 4 s periods, 10 periods,
    solve_ivp): the periods lptv.inspect says to drop leave the damping unbiased over 24 records
    (dropping the 4 that differ visibly from the steady ones left +0.9 std); lptv identify with
    fewer dropped names the transient and the periods to drop."""
    z, advice = [], []
    rigs = mass_spring_damper_many(4.0, 50.0, 10, lines=odd_lines(1, 20, seed=7), noise=0.01, seeds=range(24),
                                   damping=0.54)
    for t, f, x in rigs:
        src = tmp_path / "rig.csv"
        np.savetxt(src, np.column_stack([t, f, x]), delimiter=",", header="time,force,displacement", comments="")
        insp = lptv.inspect(src, u="force", y="displacement")
        K = insp.transient_periods
        advice.append(K)
        res = lptv.identify(f.reshape(10, -1)[K:], x.reshape(10, -1)[K:], na=2, nb=0, ka=[1, 0, 0], kb=0,
                            w0=2 * np.pi / 4, lines="excited")
        i = res.eta_names.index("a1.re0")
        z.append((res.eta[i] - 0.54) / np.sqrt(res.covariance[i, i]))
    assert abs(np.mean(z)) < 3 / np.sqrt(len(z)), (np.mean(z), advice)
    from lptv.records.scan import TRANSIENT_LEFT

    assert K >= insp.transient.seen and insp.transient.left <= TRANSIENT_LEFT and insp.transient.enough
    rc, out, err = cli_run(capsys, "identify", src, "--input", "force", "--output", "displacement", "--period", 4,
                           "--na", 2, "--nb", 0, "--ka", "1,0,0", "--lines", "excited", "--skip-periods", 4,
                           "--no-report", "--out", tmp_path / "o")
    assert rc in (0, 3), err
    assert f"first {K} periods hold a start-up transient" in out and f"--skip-periods {K} drops it" in out, out
