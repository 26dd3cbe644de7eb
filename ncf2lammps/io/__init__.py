"""File formats: LAMMPS data files, rendered decks, resolved specs, results."""
