"""Results -> Markdown + figures (pure rendering) and the report writer."""
from .markdown import Figure, Rendered, fmt, latex_matrix, md_table

__all__ = ["Figure", "Rendered", "fmt", "latex_matrix", "md_table"]
