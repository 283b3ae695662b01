"""Tests of frontend/cityengine: CityEngine CGA lowered to IR."""
