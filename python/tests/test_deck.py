import pytest

import mecano


def test_read_parameters_overrides_and_canonical_text(decks):
    deck = mecano.Deck.read(decks / "pendulum_sweep.dat")
    assert deck.name.endswith("pendulum_sweep.dat")
    params = deck.parameters
    assert "E" in params and params["E"] > 0
    soft = deck.with_parameters(E=2.1e10)
    assert soft.parameters["E"] == 2.1e10
    assert deck.parameters["E"] == params["E"]  # the original is unchanged
    # str() is the canonical text: it parses back to the same canonical text.
    again = mecano.Deck(str(soft), name="again")
    assert str(again) == str(soft)
    assert "Deck(" in repr(soft) and "E=" in repr(soft)


def test_refined_divides_the_beams(decks):
    deck = mecano.Deck.read(decks / "pendulum.dat")
    fine = deck.refined(2)
    assert fine.refine == 2
    assert len(fine.nodes) > len(deck.nodes)
    with pytest.raises(ValueError):
        deck.refined(0)


def test_deck_error_lists_every_error_with_its_place():
    text = "TITLE t\nNODES\n  1 0 0 zero\n  2 1 0 0\nELEMENTS\n  1 HINGE 1 9 AXIS 0 0 1\nEND\n"
    with pytest.raises(mecano.DeckError) as e:
        mecano.Deck(text, name="bad.dat")
    errors = e.value.errors
    assert len(errors) >= 2
    for file, line, column, message in errors:
        assert file == "bad.dat" and line >= 1 and column >= 1 and message
    assert errors[0][1] == 3
    # The message is the CLI's diagnostic: file, line and column.
    assert "bad.dat" in str(e.value)
    assert isinstance(e.value, mecano.MecanoError)


def test_missing_file_and_bad_types(tmp_path):
    with pytest.raises(mecano.DeckError) as e:
        mecano.Deck.read(tmp_path / "nope.dat")
    assert "nope.dat" in str(e.value)
    with pytest.raises(TypeError):
        mecano.Deck(42)  # type: ignore[arg-type]
    with pytest.raises(TypeError):
        mecano.run(3.5)  # type: ignore[arg-type]


def test_with_parameters_refuses_unknown_names_nan_and_strings(decks):
    deck = mecano.Deck.read(decks / "pendulum_sweep.dat")
    with pytest.raises(mecano.DeckError):
        deck.with_parameters(NOT_A_PARAMETER=1.0)
    with pytest.raises(ValueError):
        deck.with_parameters(E=float("nan"))
    with pytest.raises(ValueError):
        deck.with_parameters(E=float("inf"))
    with pytest.raises(TypeError):
        deck.with_parameters(E="soft")


def test_a_superelements_files_are_read_beside_its_deck(decks, tmp_path, monkeypatch):
    # FILES beam names decks/superelement/beam/, relative to the deck's directory: the
    # deck must find it from any working directory (issue 38), as the command line does.
    monkeypatch.chdir(tmp_path)
    deck = mecano.Deck.read(decks / "superelement" / "cantilever_se.dat")
    f = list(mecano.modes(deck, count=4)["frequency_hz"])
    # The clamped bar's first bending pair: 27.911 Hz as beams and as this superelement
    # (docs/superelements.md, equal to 1e-8), printed there to 5 digits.
    assert abs(f[0] - 27.911) < 1e-3 * 27.911, f
    # A deck remade from it (overrides) keeps the deck's directory.
    again = list(mecano.modes(deck.with_parameters(), count=4)["frequency_hz"])
    assert again == f
