"""The material with memory: a generalized Maxwell (Prony) series, read from TOML or fitted to DMA data."""
from tengsim.relaxation.prony import Prony, sls, sls_creep, sylgard184
from tengsim.relaxation.fit import DMAFit, fit_dma, read_dma
from tengsim.relaxation.read import read_relaxation, relaxation_from_table

__all__ = ["Prony", "sls", "sls_creep", "sylgard184", "DMAFit", "fit_dma", "read_dma",
           "read_relaxation", "relaxation_from_table"]
