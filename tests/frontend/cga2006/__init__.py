"""Tests of frontend/cga2006: the paper notation lowered to IR."""
