"""The pipeline: an input and a map specification -> a map run."""
