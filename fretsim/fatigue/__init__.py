"""Fretting fatigue beside wear (issue 34): the stresses under the contact and the crack-initiation life they give.

* :mod:`.stresses` — the plane-strain half-space's stresses under piecewise-constant normal and shear tractions
  (closed forms of the strips' line-load integrals);
* :mod:`.swt` — the Smith–Watson–Topper parameter on the critical plane, its life from the Basquin–Coffin–Manson
  curve, and Ruiz's fretting damage parameter.
* :mod:`.stresses3d` — the same for the 3D half-space on a grid (rectangles by FFT); :func:`.swt.swt_search_3d`
  over plane normals; :mod:`.field3d` — the flat's fields below a 3D contact at a fatigue state (the moving
  body's fatigue is 2D only);
* :mod:`.history` — a cycle's tractions laid on the flat and its stresses over the cycle (by FFT); the moving
  body's, at its own points under (p, −q), by the same convolution (:mod:`.damage`);
* :mod:`.damage` — the fatigue states, each body's SWT field and life at each, and Miner's sum over the wear
  history (what the loop, :mod:`fretsim.loop.fatigue`, calls).
"""
