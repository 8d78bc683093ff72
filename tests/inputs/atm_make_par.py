#!/usr/bin/env python3
"""Writes atm_h2o_subset.csv and atm_h2o_o2_subset.par for test_atm_lines.c: the
H2O lines of data/atmosphere/am14_h2o_lines.csv below 1.2 THz with S296 above
1e-24 cm^2 GHz, as the same am CSV rows and as HITRAN 160-character records built
from the CSV's HITRAN-unit columns; the .par also carries a few O2 (molecule 7)
records, which an H2O catalogue must skip. Run from this directory."""
import csv

src = "../../data/atmosphere/am14_h2o_lines.csv"
o2src = "../../data/atmosphere/am14_o2_lines_uncoupled.csv"


def rows(path):
    lines = [l for l in open(path) if not l.startswith("#")]
    return list(csv.DictReader(lines)), lines[0]


def fortran_f(value, width, decimals):
    s = "%*.*f" % (width, decimals, value)
    if len(s) > width:  # Fortran drops the leading zero: F5.4 of 0.0587 is .0587
        s = s.replace("0.", ".", 1)
    assert len(s) == width, (value, s)
    return s


def record(mol, r):
    s = "%2d%1d" % (mol, int(r["hitran_iso"]))
    s += fortran_f(float(r["nu_cm-1"]), 12, 6)
    s += "%10.3E" % float(r["S296_cm-1_per_molec_cm-2"])
    s += "%10.3E" % 0.0  # Einstein A: not used
    s += fortran_f(float(r["gamma_air_cm-1_per_atm"]), 5, 4)
    s += fortran_f(float(r["gamma_self_cm-1_per_atm"]), 5, 3)
    s += fortran_f(float(r["Elower_cm-1"]), 10, 4)
    s += fortran_f(float(r["n_air"]), 4, 2)
    s += fortran_f(float(r["delta_air_cm-1_per_atm"]), 8, 6)
    s += " " * 60 + "000000" + " " * 12 + " " + "%7.1f%7.1f" % (0.0, 0.0)
    assert len(s) == 160
    return s


h2o, header = rows(src)
keep = [r for r in h2o if float(r["freq_GHz"]) < 1200 and float(r["S296_cm2_GHz"]) > 1e-24]
o2, _ = rows(o2src)
o2keep = [r for r in o2 if 350 < float(r["freq_GHz"]) < 800 and float(r["S296_cm2_GHz"]) > 1e-25]
with open("atm_h2o_subset.csv", "w") as f:
    f.write("# Subset of data/atmosphere/am14_h2o_lines.csv (am 14.0, S. Paine, SAO; AER/HITRAN line data), made by atm_make_par.py\n")
    f.write(header)
    w = csv.DictWriter(f, fieldnames=header.strip().split(","), lineterminator="\n")
    for r in keep:
        w.writerow(r)
with open("atm_h2o_o2_subset.par", "w") as f:
    for r in sorted([(float(r["nu_cm-1"]), 1, r) for r in keep] + [(float(r["nu_cm-1"]), 7, r) for r in o2keep], key=lambda t: t[0]):
        f.write(record(r[1], r[2]) + "\n")
print(len(keep), "H2O lines,", len(o2keep), "O2 lines")
