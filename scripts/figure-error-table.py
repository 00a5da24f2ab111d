#!/usr/bin/env python3
"""Writes datasets-synthetic/sensors/ohte-sph-figure-error.csv: the seed's spherical mirror
(radius of curvature A = 49.9582 mm, rim 43.9 mm) with a 20 um zonal figure error, as a
polishing shop leaves one: z(r) = A - sqrt(A^2 - r^2) + e(r), e(r) = 20 um (cos(3 pi u) - 1),
u = (r / rim)^2 (zero and flat at the vertex, 1.5 waves in u across the mirror, slope error up
to 7.9e-3 rad inside the rim, near r = 40 mm). Rows r, z, dz/dr in mm (the tabulated
profile's format), r from the vertex to 0.999 A, 2001 rows. No shipped formula matches it: `calibrate --profile spline`
must follow it (tests/cli/figure_error_test.sh).
Usage: scripts/figure-error-table.py OUTPUT.csv"""
import math
import sys

A_MM, RIM_MM, ERROR_MM, ROWS = 49.9582, 43.9, 0.020, 2001

with open(sys.argv[1], "w") as out:
    for i in range(ROWS):
        r = 0.999 * A_MM * i / (ROWS - 1)
        root = math.sqrt(A_MM * A_MM - r * r)
        u = (r / RIM_MM) ** 2
        z = A_MM - root + ERROR_MM * (math.cos(3 * math.pi * u) - 1)
        slope = r / root - ERROR_MM * math.sin(3 * math.pi * u) * 6 * math.pi * r / RIM_MM ** 2
        out.write("%.9f,%.9f,%.9f\n" % (r, z, slope))
