"""Earthquake input and response: records, response spectra."""
