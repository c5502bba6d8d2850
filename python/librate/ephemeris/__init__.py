"""The Earth-Moon-Sun ephemeris model: SPK files (spk), epochs (epochs)."""
