"""Output at the edge: XDMF fields, JSON and CSV records, pictures and plots."""
