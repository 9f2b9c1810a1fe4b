"""Helpers shared by the tests: synthetic frames, raw bag writers, map checks, a browser."""
