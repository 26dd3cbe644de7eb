"""Analysis: pure numpy (and MDAnalysis) on positions and recorded curves; plots."""
