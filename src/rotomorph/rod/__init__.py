"""Rod layer: discrete elastic rod (DER) model of filaments and rod networks."""
