"""The registered friction elements of a mount axis, in FMU code order
(``<axis>_friction_kind``): one line per element. Append new elements at the end
(the FMU's codes and value references of the earlier ones stay)."""

from .berg import BERG
from .dahl import DAHL
from .friction import register_element
from .inclined_element import INCLINED
from .jenkins import JENKINS
from .lugre import LUGRE

for _element in (JENKINS, INCLINED, DAHL, LUGRE, BERG):
    register_element(_element)
