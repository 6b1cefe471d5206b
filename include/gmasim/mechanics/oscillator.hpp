// Forwarding header: the oscillator update of eq. (15) is a physics law,
// gmasim/physics/oscillator.hpp (issue 38: no header includes one of a higher layer).
#pragma once

#include "gmasim/physics/oscillator.hpp"
