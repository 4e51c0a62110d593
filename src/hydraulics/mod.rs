//! Hydraulic components of the circuit of thesis Fig. 2.8, one file per component.
