#!/usr/bin/env python3
"""Writes the line lists of test_atm_lines.c. Run from this directory.

atm_h2o_subset.csv, atm_h2o_o2_subset.par: the H2O lines of
data/atmosphere/am14_h2o_lines.csv below 1.2 THz with S296 above 1e-24 cm^2 GHz, as
the same am CSV rows and as HITRAN 160-character records built from the CSV's
HITRAN-unit columns; the .par also carries a few O2 (molecule 7) records, which an
H2O catalogue must skip.

atm_o2_subset.csv, atm_o2_with_coupled.par: the uncoupled O2 lines below 140 GHz
with S296 above 1e-29 cm^2 GHz,
as CSV and as .par; the .par also holds the 60 GHz band and 118.75 GHz lines of
am14_o2_lines_coupled.csv, 1 MHz off as a HITRAN list may have them, which the
reader must drop (the coupled table already has them, with line mixing)."""
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
o2, header_o2 = rows(o2src)
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


def hitran_from_am(r, shift_ghz=0.0):
    c, k, atm = 29.9792458, 1.4387769, 1013.25
    return {"hitran_iso": r["hitran_iso"],
            "nu_cm-1": (float(r["freq_GHz"]) + shift_ghz) / c,
            "S296_cm-1_per_molec_cm-2": float(r["S296_cm2_GHz"]) / c,
            "gamma_air_cm-1_per_atm": float(r["gamma_air_GHz_per_mbar"]) * atm / c,
            "gamma_self_cm-1_per_atm": float(r["gamma_self_GHz_per_mbar"]) * atm / c,
            "Elower_cm-1": max(float(r["Elower_K"]), 0.0) / k,
            "n_air": float(r["n_air"]),
            "delta_air_cm-1_per_atm": float(r["delta_air_GHz_per_mbar"]) * atm / c}


o2low = [r for r in o2 if float(r["freq_GHz"]) < 140 and float(r["S296_cm2_GHz"]) > 1e-29]
coupled, _ = rows("../../data/atmosphere/am14_o2_lines_coupled.csv")
coupled = [r for r in coupled if float(r["freq_GHz"]) > 1]  # not the Debye pseudo-line
with open("atm_o2_subset.csv", "w") as f:
    f.write("# Subset of data/atmosphere/am14_o2_lines_uncoupled.csv (am 14.0, S. Paine, SAO; HITRAN2020), made by atm_make_par.py\n")
    f.write(header_o2)
    w = csv.DictWriter(f, fieldnames=header_o2.strip().split(","), lineterminator="\n")
    for r in o2low:
        w.writerow(r)
with open("atm_o2_with_coupled.par", "w") as f:
    recs = [(float(r["nu_cm-1"]), record(7, r)) for r in o2low]
    recs += [(h["nu_cm-1"], record(7, h)) for h in (hitran_from_am(r, 0.001) for r in coupled)]
    for _, rec in sorted(recs):
        f.write(rec + "\n")
print(len(o2low), "uncoupled and", len(coupled), "coupled O2 lines")
