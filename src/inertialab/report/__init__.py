"""Figures (matplotlib) and the self-contained HTML report. The report renders; it
does not compute: every number comes from a workflow result."""
