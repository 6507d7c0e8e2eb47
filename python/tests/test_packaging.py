"""The installed package says what it is: the MIT license in its metadata and the license text beside it."""

from __future__ import annotations

from importlib import metadata


def test_the_package_is_mit_licensed_and_ships_the_license_text():
    assert metadata.metadata("exactgeo")["License-Expression"] == "MIT"
    files = [f for f in metadata.files("exactgeo") or [] if f.name == "LICENSE"]
    assert files, "LICENSE is not installed with the package"
    assert "MIT License" in files[0].read_text()
