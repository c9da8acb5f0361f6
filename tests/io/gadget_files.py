#!/usr/bin/python3
"""Gadget-format HDF5 files written by h5py, an HDF5 writer independent of
swirl's, for tests/io/snapshot_test.cpp.

    gadget_files.py KIND PATH

KIND "ics" is a valid set of initial conditions in the form the community's
generators write (five type-1 particles, the mass in MassTable, no Masses and
no Velocities datasets, float32 coordinates); "gas_and_halo" adds three type-0
particles with float64 Masses and Velocities of their own (read one type at a
time, for tests/scene/snapshot_source_test.cpp), "nbody_units" says
UnitSystem = "nbody" and "kpc_units" has a /Units group in kpc, 1e10 Msun and
km/s (SWIFT's attribute names). Every other kind is the "ics" file with one
thing wrong, which swirl must refuse naming it.
"""
import sys

import h5py
import numpy as np


def write(kind, path):
    n = 5
    with h5py.File(path, "w") as f:
        counts = np.zeros(6, dtype=np.uint32)
        counts[1] = n
        if kind == "two_types":
            counts[0] = 2
        mass_table = np.zeros(6)
        if kind != "no_mass":
            mass_table[1] = 0.2
        if kind != "no_header":
            h = f.create_group("Header")
            h.attrs["NumPart_ThisFile"] = counts
            h.attrs["NumPart_Total"] = counts
            h.attrs["NumPart_Total_HighWord"] = np.zeros(6, dtype=np.uint32)
            h.attrs["MassTable"] = mass_table
            h.attrs["Time"] = 0.5
            h.attrs["Redshift"] = 0.0
            h.attrs["BoxSize"] = 0.0
            h.attrs["NumFilesPerSnapshot"] = 2 if kind == "split" else 1
            if kind == "future":
                h.attrs["SwirlFormatVersion"] = 99
            if kind == "nbody_units":
                h.attrs["UnitSystem"] = np.bytes_(b"nbody")
            if kind == "gas_and_halo":
                counts[0] = 3
                h.attrs["NumPart_ThisFile"] = counts
                h.attrs["NumPart_Total"] = counts
        if kind == "kpc_units":
            u = f.create_group("Units")
            for name, value in [("Unit length in cgs (U_L)", 3.08567758e21), ("Unit mass in cgs (U_M)", 1.98841e43),
                                ("Unit time in cgs (U_t)", 3.08567758e16), ("Unit current in cgs (U_I)", 1.0),
                                ("Unit temperature in cgs (U_T)", 1.0)]:
                u.attrs[name] = np.array([value])
        if kind == "gas_and_halo":
            gas = f.create_group("PartType0")
            gas["Coordinates"] = np.array([[0.5, -0.25, 1.0 / 3.0], [-0.0, 2.0, 1e-300], [-1.5, 0.125, 7.0]])
            gas["Velocities"] = np.array([[1.0, 2.0, 3.0], [-0.0, 0.1, -0.2], [4.0, 5.0, 6.0]])
            gas["Masses"] = np.array([0.3, 0.1, 0.7])
            gas["ParticleIDs"] = np.arange(3, dtype=np.uint64)
        g = f.create_group("PartType1")
        x = np.zeros((n, 3), dtype=np.float32)
        x[:, 1] = 0.1 * np.arange(n)
        if kind == "flat_coordinates":
            g["Coordinates"] = x[:, 0]
        elif kind == "string_coordinates":
            g["Coordinates"] = np.array([b"a", b"b", b"c", b"d", b"e"])
        elif kind != "no_coordinates":
            g["Coordinates"] = x
        g["ParticleIDs"] = np.arange(10, 10 + n, dtype=np.uint64)
        if kind == "short_masses":
            g["Masses"] = np.full(n - 1, 0.2)
        if kind == "nan_velocity":
            v = np.zeros((n, 3))
            v[3, 0] = np.nan
            g["Velocities"] = v
        if kind == "two_types":
            f.create_group("PartType0")["Coordinates"] = np.zeros((2, 3))


if __name__ == "__main__":
    write(sys.argv[1], sys.argv[2])
