"""Elastic kernels (paper Eq. 9): the half-space and the film on a rigid substrate, free or periodic."""
from tengsim.kernels.base import make_kernel, pixel_influence
from tengsim.kernels.film import film_pixel_correction
from tengsim.kernels.halfspace import FreeKernel, PeriodicKernel

__all__ = ["FreeKernel", "PeriodicKernel", "film_pixel_correction", "make_kernel", "pixel_influence"]
