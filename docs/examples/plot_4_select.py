"""
Which orders and how many harmonics? ``lptv.select``
====================================================

A grid of structures (na, nb, k harmonics on every coefficient) is fitted by WGTLS on the same
lines; the best two per harmonic count are refitted by the exact likelihood (SML) and ranked by
MDL, never choosing one the residue test rejects while another passes. The data are the
paper's example; its true structure is (2, 1, 3).
"""
import lptv
from lptv.examples import PAPER_ID_LINES, paper_measurements

m = paper_measurements(seed=1, periods=8)
sel = lptv.select(m["u"], m["y"], w0=m["w0"], na=range(1, 4), nb=range(0, 3), k=range(2, 5),
                  lines=PAPER_ID_LINES, executor="serial", progress=False)
print(sel.summary(6))
print("chosen (na, nb, k):", sel.choice)
