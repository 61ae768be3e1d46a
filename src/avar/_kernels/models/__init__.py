"""Compiled loops of the latent models: ``covariance`` (the Allan variance of a covariance matrix) and ``simulation``."""
