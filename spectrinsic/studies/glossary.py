"""What the studies' printed tables abbreviate, and how a number is set beside the thesis'.

Every study's text output ends with the meaning of each abbreviation it used
(:func:`abbreviations`), and every number that has a thesis value is printed with the
difference and, where it is known, its cause (:func:`versus_thesis`), so a large gap never
stands without a comment.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = ["STUDY_TERMS", "abbreviations", "versus_thesis"]

#: Every abbreviation a study prints, with its meaning (thesis equations and sections).
STUDY_TERMS: dict[str, str] = {
    "SC1": "photometric scenario 1: camera sensors and light known, full 3x3 light model "
    "(estimate S_Sen^-1 L_CLig^-1 p; thesis Table 4.3)",
    "SC2": "scenario 2: sensors and light known, diagonal light model (S_Sen^-1 D^-1 p)",
    "SC3": "scenario 3: light known, sensors unknown (taken as sRGB): D^-1 p",
    "SC4": "scenario 4: nothing known (D65 and sRGB sensors assumed): p as it stands",
    "A_vs_B": "mean over (camera, light set) of (error A - error B) / error B, in %",
    "ε": "relative reconstruction error ‖p - p̂‖₂ / ‖p‖₂ of the diagonal model (thesis Eq. 5.7), %",
    "s.d.": "population standard deviation (ddof = 0)",
    "b": "bounces of light (1: direct; 2: one interreflection)",
    "two-pass": "the thesis' method: render 6 diagonal channels, then project them back to colour "
    "by a linear regression fitted over the reflectances",
    "ΔE2000": "CIEDE2000 colour difference (Lab relative to the D65 white); about 1 is just visible",
    "e3": "ε (Eq. 5.7, %) per pixel of the rgb3 render (CIE 1931 CMFs as 3 diagonal sensors) "
    "against the 31-band reference",
    "e3g": "the same for gauss3 (3 Gaussian sensors, thesis Table 5.2's set, regressed to XYZ)",
    "e6": "the same for rgb6 (6 Gaussian sensors, the two-pass method, regressed to XYZ)",
    "r": "energy ratio of thesis Eq. 5.8: direct light over all bounces, Σ‖p¹‖ / Σ‖p^∞‖",
    "v": "camera viewpoint of the scene",
    "LMSE": "local mean squared error (Grosse et al. 2009; thesis Table 3.2): 20-pixel windows, "
    "shift 10, one least-squares scale per window, normalised by the ground truth's energy; "
    "the mean of shading and grey reflectance",
    "CI": "confidence interval: mean ± t_{0.975, n-1} s / √n over the seeds (Student's t)",
    "rgb3": "the 3-sensor render (CIE 1931 CMFs as 3 diagonal sensors) of the same scene",
}


def abbreviations(terms: Iterable[str]) -> str:
    """The "Abbreviations" block for *terms* (each a key of :data:`STUDY_TERMS`), one a line.

    >>> print(abbreviations(["b", "s.d."]))
    Abbreviations:
      b     bounces of light (1: direct; 2: one interreflection)
      s.d.  population standard deviation (ddof = 0)
    """
    names = list(dict.fromkeys(terms))
    width = max(len(n) for n in names)
    return "\n".join(["Abbreviations:", *(f"  {n:<{width}}  {STUDY_TERMS[n]}" for n in names)])


def versus_thesis(ours: float, thesis: float, *, digits: int = 2, cause: str | None = None) -> str:
    """``ours - thesis`` as printed beside a number, with its *cause* where it is known.

    >>> versus_thesis(0.71, 0.83)
    '-0.12 vs thesis 0.83'
    >>> versus_thesis(110.0, 48.0, digits=0, cause="see note")
    '+62 vs thesis 48 (see note)'
    """
    diff = round(ours - thesis, digits) + 0.0  # + 0.0: no "-0.00"
    text = f"{diff:+.{digits}f} vs thesis {thesis:.{digits}f}"
    return f"{text} ({cause})" if cause else text
