"""The measured record before any model (METHOD.md section 18).

- :mod:`lptv.records.measurements`: :func:`lptv.read_measurements` (CSV, NPZ, MATLAB);
  :mod:`lptv.records.channels` which of a file's arrays are the input, the output and the time;
- :mod:`lptv.records.check`: :func:`lptv.check_record` (transient, drift, wrong cut) and the
  drift's removal;
- :mod:`lptv.records.inspection`: :func:`lptv.inspect`, what a record holds;
  :mod:`lptv.records.scan` the scans it runs (period, transient, line classes).
"""
