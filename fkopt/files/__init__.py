"""Shared file helpers (floor 0): bounded reading, safe YAML, safe output paths,
write-aside-then-swap, one-line error messages. Every config file, geometry file, outside file
and results folder of fkopt goes through this package, once:

* :mod:`.reading` -- the one bounded reader of every file fkopt did not write in this run
  (:func:`read_input`: regular files only, inside the folder they were named from, a size cap
  checked before reading, ``.gz`` streamed with a cap on the unpacked size), with
  :func:`read_text`, :func:`read_json` (strict JSON), :func:`parse_xml` (URDF, MJCF: nesting
  bounded while parsing), :func:`read_stored` (stored results) and :func:`odd_entries` (what a
  results folder must not hold) on top.
* :mod:`.csv_reading` -- CSV parsed with memory bounded whatever the bytes (:func:`parse_csv`).
* :mod:`.yaml_reading` -- :func:`load_yaml`, the one YAML reader (no aliases, no duplicate keys,
  bounded depth, finite numbers, plain data only).
* :mod:`.validation` -- one line ``field.path: message`` from a pydantic error
  (:func:`error_line`), :func:`did_you_mean`, :func:`no_quoted_numbers`, :func:`check_component`
  (``paper`` and ``name`` as single safe path components), :data:`MAX_MAGNITUDE`.
* :mod:`.writing` -- :func:`output_folder` (checked before any computation), :func:`inside` (the
  one output-path guard), :func:`write_atomically` (a folder written aside, then swapped into
  place), :func:`write_file_atomically`, :func:`run_lock`, :func:`file_names`.
* :mod:`.text` -- :func:`strict_json` (every ``--json``), :func:`md_text`, :func:`one_line`,
  :func:`short_token`.
* :mod:`.numbers` -- :func:`nanmedian`; :mod:`.host` -- :func:`available_cpus`, :func:`installed_version`,
  :func:`sigint_handler`.

Every name is importable from ``fkopt.files`` itself (``from fkopt.files import read_input``),
as callers have always written it; a test that replaces a bound patches the module that reads it
(``fkopt.files.csv_reading.MAX_CSV_CELLS``).
"""
from __future__ import annotations

from fkopt.files.csv_reading import (MAX_CSV_CELLS, MAX_CSV_COLUMNS, MAX_CSV_LINE, check_csv_shape, csv_numbers,
                                     parse_csv, read_csv, read_stored_csv)
from fkopt.files.host import available_cpus, installed_version, sigint_handler
from fkopt.files.numbers import nanmedian
from fkopt.files.reading import (MAX_INPUT_BYTES, MAX_UNPACKED, MAX_XML_DEPTH, MAX_YAML_BYTES, check_geometry_file,
                                 check_within, odd_entries, open_input, parse_json, parse_xml, png_size, read_input, read_json,
                                 read_stored, read_text, stored_sha256, where_named)
from fkopt.files.text import md_table, md_text, one_line, short_token, strict_json
from fkopt.files.validation import (COMPONENT_PATTERN, MAX_COMPONENT, MAX_MAGNITUDE, check_component, did_you_mean,
                                    error_line, field_names_at, field_path, models_in, no_quoted_numbers)
from fkopt.files.writing import (file_names, inside, naming_the_file, no_empty_folders_left, output_folder, run_lock,
                                 swap_into_place, write_atomically, write_file_atomically, write_json,
                                 write_json_atomically)
from fkopt.files.yaml_reading import MAX_YAML_DEPTH, load_mapping, load_yaml

__all__ = ["COMPONENT_PATTERN", "MAX_COMPONENT", "MAX_CSV_CELLS", "MAX_CSV_COLUMNS", "MAX_CSV_LINE",
           "MAX_INPUT_BYTES", "MAX_MAGNITUDE", "MAX_UNPACKED", "MAX_XML_DEPTH", "MAX_YAML_BYTES", "MAX_YAML_DEPTH",
           "available_cpus", "check_component", "check_csv_shape", "check_geometry_file", "check_within",
           "csv_numbers", "did_you_mean", "error_line", "field_names_at", "field_path", "file_names", "inside",
           "load_mapping", "load_yaml", "md_table", "md_text", "models_in", "nanmedian", "naming_the_file",
           "no_empty_folders_left", "no_quoted_numbers", "odd_entries", "one_line", "open_input", "output_folder",
           "parse_csv", "parse_json", "parse_xml", "read_csv", "read_input", "read_json", "read_stored",
           "read_stored_csv", "read_text", "run_lock", "short_token", "stored_sha256", "strict_json",
           "swap_into_place", "where_named", "write_atomically", "write_file_atomically", "write_json",
           "write_json_atomically"]
