"""Result files: the layout (format 2), rows, the single writer and its HDF5 storage, readers
(format 1 and 2), safe outputs, the xarray view and tables. Imports result and below.
"""
