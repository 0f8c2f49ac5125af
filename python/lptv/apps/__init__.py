"""The ``lptv`` command line and its jobs, built on the public API of :mod:`lptv`.

- :mod:`lptv.apps.cli` - the ``lptv`` command (``python -m lptv`` runs it too);
- :mod:`lptv.apps.demo` - ``lptv demo``: the paper's simulation example end to end;
- :mod:`lptv.apps.lecture` - ``lptv demo lecture``: the lecture's identification cases;
- :mod:`lptv.apps.fileid` - ``lptv identify FILE``: a model from a measurement file;
- :mod:`lptv.apps.report` - the offline HTML report they write.
"""
