"""The analysis layer: trade-off tables, per-seed measures of the claims' checks, comparisons,
verdicts with their evidence and uncertainty, and the report's tables built from them."""
