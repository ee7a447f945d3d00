"""Shapes: the initial gap U0 >= 0 of the elastic surface (paper Eq. 11), one module per family.

Importing this package registers the built-in shapes in :data:`tengsim.registry.SHAPES`, exactly as a
plugin's module registers its own.
"""
from tengsim.shapes.base import Shape, dimensionless_fields, physical_fields
from tengsim.shapes.heightmap import HeightMap
from tengsim.shapes.pyramid import Pyramid
from tengsim.shapes.axisymmetric import Cone, FlatPunch, Hemisphere, Paraboloid
from tengsim.shapes.flat_topped import Cube, Line
from tengsim.shapes.periodic import Sinusoid1D, random_rough
from tengsim.shapes.rough import Rough
from tengsim.shapes.roughened import Roughened
from tengsim.shapes.topography import Topography
from tengsim.shapes.arrays import Array

__all__ = ["Array", "Cone", "Cube", "FlatPunch", "HeightMap", "Hemisphere", "Line", "Paraboloid", "Pyramid",
           "Rough", "Roughened", "Shape", "Sinusoid1D", "Topography", "dimensionless_fields", "physical_fields", "random_rough"]
