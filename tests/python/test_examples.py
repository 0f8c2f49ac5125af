"""lptv.examples: the examples in its docstrings run as printed."""
import doctest

import lptv.examples.siso


def test_docstring_examples_run():
    result = doctest.testmod(lptv.examples.siso, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0
