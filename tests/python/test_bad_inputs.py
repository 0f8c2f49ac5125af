"""Every bad input through the public Python API and the command line gives a clear error naming
the argument (or the option, or the file): the table of cases is bad_input_cases.py, run by
bad_input_runner.py.

Python cases run in child interpreters (a crash there fails its case, not the session); each
command-line case runs in its own process and must exit with status 2 and one line on stderr,
without a traceback. bench/python/bad_inputs.py counts the outcomes of the same table.
"""
import argparse

import pytest

import bad_input_cases as table
import bad_input_runner as runner
import lptv

PY = table.python_cases()
CLI = table.cli_cases()


@pytest.fixture(scope="module")
def py_outcomes():
    from concurrent.futures import ThreadPoolExecutor

    ids = [c.id for c in PY]
    with ThreadPoolExecutor(2) as ex:   # two child interpreters side by side
        parts = list(ex.map(runner.run_python_cases, [ids[0::2], ids[1::2]]))
    return {**parts[0], **parts[1]}


@pytest.fixture(scope="module")
def cli_outcomes():
    return runner.run_cli_cases(CLI, workers=2)


@pytest.mark.parametrize("case", PY, ids=[c.id for c in PY])
def test_python_api(case, py_outcomes):
    outcome, detail = py_outcomes[case.id]
    assert outcome == case.expected, f"{case.klass}: {detail}"


@pytest.mark.parametrize("case", CLI, ids=[c.id for c in CLI])
def test_command_line(case, cli_outcomes):
    outcome, detail = cli_outcomes[case.id]
    assert outcome == case.expected, detail


# ------------------------------------------------------------------ the table's coverage

# names of lptv.__all__ that take no arguments from a user: exceptions, warnings, a constant, and
# result records the library builds (their methods that take arguments have cases of their own)
NOT_CALLED_BY_USERS = {"NumericalError", "IdentifiabilityWarning", "TruncationWarning", "RecordWarning",
                       "ConditioningWarning", "UnstableModelWarning", "StabilityUndecidedWarning",
                       "METHODS", "CramerRaoBound", "FloquetResult", "SimulationResult", "RecordCheck",
                       "Measurements", "RecordResult", "ModeratedNoise", "Disturbance", "DisturbanceResult",
                       "LackOfFit", "Inspection", "LineClass", "MimoMultisines",
                       "MimoHtfEstimate", "MimoIdentificationResult", "MimoCramerRaoBound", "ValidationResult",
                       "CoefficientTest", "LineCorrelation"}


@pytest.mark.parametrize("name", sorted(set(lptv.__all__) - NOT_CALLED_BY_USERS))
def test_every_public_name_has_bad_inputs(name):
    prefixes = {c.id.split("-")[0].split(".")[0] for c in PY}
    # Model's class methods have ids of their own: from_tf, load, save, freqresp, a_at ...
    assert name in prefixes, f"no bad-input case for lptv.{name}"


def _options():
    """{command: option strings} of the lptv command, from the parsers the command builds."""
    from lptv.apps import choose, cli, fileid, inspectrec, montecarlo

    top = argparse.ArgumentParser(prog="lptv")
    sub = top.add_subparsers(dest="command")
    parsers = {"demo": cli._demo_parser(sub), "identify": fileid.add_parser(sub),
               "montecarlo": montecarlo.add_parser(sub), "select": choose.add_parser(sub),
               "inspect": inspectrec.add_parser(sub)}
    out = {}
    for command, p in parsers.items():
        out[command] = {s for a in p._actions for s in a.option_strings
                        if s.startswith("--") and s != "--help" and a.nargs != 0}
    return out


@pytest.mark.parametrize("command, option", [(c, o) for c, opts in sorted(_options().items()) for o in sorted(opts)])
def test_every_option_that_takes_a_value_has_bad_values(command, option):
    used = [c for c in CLI if c.argv[0] == command and option in c.argv
            and c.argv.index(option) + 1 < len(c.argv)]
    assert used, f"no bad-value case for lptv {command} {option}"


@pytest.mark.parametrize("klass", ["type", "nan/inf", "shape", "size", "range", "overflow", "file", "value"])
def test_every_class_of_bad_value_is_present(klass):
    assert sum(c.klass == klass for c in PY) >= 5


# ----------------------------------------------------------------------- the runner itself

def test_the_runner_reports_a_crash_and_goes_on():
    out = runner.run_python_cases([runner.SELFTEST_CRASH, "Model-w0-str"])
    assert out[runner.SELFTEST_CRASH][0] == "crash"
    assert out["Model-w0-str"][0] == "clear error"


def test_the_runner_reports_a_silent_wrong_result():
    out = runner.run_python_cases([runner.SELFTEST_SILENT])
    assert out[runner.SELFTEST_SILENT][0] == "silent wrong result"


def test_classify_tells_unclear_from_clear_errors():
    def raises(exc):
        raise exc

    case = table.Case("x", "type", lambda: raises(ValueError("w0 must be a number")), match=table.names("w0"))
    assert runner.classify(case)[0] == "clear error"
    case = table.Case("x", "type", lambda: raises(TypeError("w0 must be a number")), match=table.names("w0"))
    assert runner.classify(case)[0] == "unclear error"            # the wrong type
    case = table.Case("x", "type", lambda: raises(ValueError("could not convert string to float: 'abc'")),
                      match=table.names("w0"))
    assert runner.classify(case)[0] == "unclear error"            # does not name w0
    case = table.Case("x", "value", lambda: 2.0, check=lambda v: v == 3.0)
    assert runner.classify(case)[0] == "silent wrong result"      # a wrong answer


@pytest.mark.parametrize("status, stderr, outcome", [
    (2, "lptv identify: error: --na must be >= 0, got -1\n", "clear error"),
    (2, "usage: lptv identify ...\nlptv identify: error: argument --na: invalid int value: 'x'\n",
     "unclear error"),                                               # two lines
    (1, "Traceback (most recent call last):\n  ...\nMemoryError\n", "crash"),
    (2, "lptv identify: error: something went wrong\n", "unclear error"),   # does not name --na
    (0, "", "silent wrong result"),
    (-11, "", "crash"),
    ("timeout", "", "crash"),
])
def test_the_command_line_judge(status, stderr, outcome):
    case = table.Case("x", "cli", argv=("identify",), match="--na")
    assert runner._judge(case, status, stderr)[0] == outcome


def test_forked_commands_agree_with_python_m_lptv(tmp_path):
    """The suite forks each command from a process that has imported lptv; a sample of cases run
    as ``python -m lptv`` from scratch gives the same outcome."""
    sample = [c for c in CLI if c.id in {
        "cli-identify-na-abc", "cli-identify-lines-1-99999999999", "cli-identify-out-proc",
        "cli-select-k-1-2147483648", "cli-montecarlo-seed--1", "cli-demo-out-proc", "cli-no-command",
        "cli-identify-file-transposed.npz"}]
    assert len(sample) == 8
    table.cli_files(tmp_path)
    forked = runner.run_cli_cases(sample, workers=2)
    for c in sample:
        assert runner.run_cli_case(c, tmp_path)[0] == forked[c.id][0] == "clear error", c.id
