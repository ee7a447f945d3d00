"""Elastic kernels (paper Eq. 9): the half-space and the film on a rigid substrate, free or periodic."""
from tengsim.kernels.base import make_kernel, pixel_influence
from tengsim.kernels.film import film_pixel_correction
from tengsim.kernels.halfspace import FreeKernel, PeriodicKernel
from tengsim.kernels.mirror import MirrorKernel, make_mirror_kernel

__all__ = ["FreeKernel", "MirrorKernel", "PeriodicKernel", "film_pixel_correction", "make_kernel",
           "make_mirror_kernel", "pixel_influence"]
