"""Paper 000: structural-parametric synthesis of adaptive gripper fingers with
variable-length links (VLL).

* :mod:`~mechsyn.synthesis.finger.groups`: the table of groups of links to attach
  (``mechsyn synth groups``);
* :mod:`~mechsyn.synthesis.finger.candidates`: every distinct finger made fully actuated
  by attaching a group, with its VLL candidates (``mechsyn synth finger``);
* :mod:`~mechsyn.synthesis.finger.vll`: the cylinder-piston pair of a VLL, the locked
  model, the working-region test;
* :mod:`~mechsyn.synthesis.finger.cases`: finger-design case files;
* :mod:`~mechsyn.synthesis.finger.evaluation`: a design vector drawn as a mechanism and
  evaluated with its VLL locked (step 8's objective terms);
* :mod:`~mechsyn.synthesis.finger.population`: the same evaluation for a population at
  once, through the batch kinematics;
* :mod:`~mechsyn.synthesis.finger.modes`: the VLL range and the static forces in both
  modes (steps 9-12);
* :mod:`~mechsyn.synthesis.finger.design`: the parametric steps 8-13 driven end to end
  (:func:`~mechsyn.synthesis.finger.design.design_finger`, ``mechsyn synth finger-design``).

Each module imports only the ones listed before it (and the kinematics), so the design
driver sits on top.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""
