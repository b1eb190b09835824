"""Paper 000: structural-parametric synthesis of adaptive gripper fingers with
variable-length links (VLL).

* :mod:`~mechsyn.synthesis.finger.groups`: the table of groups of links to attach
  (``mechsyn synth groups``);
* :mod:`~mechsyn.synthesis.finger.candidates`: every distinct finger made fully actuated
  by attaching a group, with its VLL candidates (``mechsyn synth finger``);
* :mod:`~mechsyn.synthesis.finger.cases`: finger-design case files;
* :mod:`~mechsyn.synthesis.finger.vll`: the cylinder-piston pair of a VLL, the locked
  model, the working-region test;
* :mod:`~mechsyn.synthesis.finger.design`: the parametric steps 8-13
  (``mechsyn synth finger-design``).

References
----------
*Algorithm of structural-parametric synthesis of mechanisms of fingers of universal
gripping devices with variable-length links* (in Russian; ITMO University); paper 000 of
the project's seeds, restated in the spec's ``structural.md`` section 4. Its full reference:
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""
