"""The modes of the rotating cantilever (decks/rotating_cantilever.dat) against the hub's
speed: centrifugal stiffening (a Campbell diagram), the numbers of `mecano-rs modes
--rotating`.

    python examples/python/rotating_cantilever_modes.py
"""
import pathlib

import mecano

root = pathlib.Path(__file__).resolve().parents[2]
deck = mecano.Deck.read(root / "decks" / "rotating_cantilever.dat")
print("OMEGA (rad/s)  lowest frequencies (Hz)")
for omega in [0.0, 2.0, 4.0, 6.0, 8.0, 10.0]:
    m = mecano.modes(deck.with_parameters(OMEGA=omega), count=3, rotating=True)
    print(f"{omega:12.1f}  " + "  ".join(f"{f:8.4f}" for f in m["frequency_hz"]))
