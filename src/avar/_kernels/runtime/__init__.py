"""How the kernels run: ``tasks`` (nogil task kernels on a few Python threads) and ``cache`` (where numba's cache goes)."""
