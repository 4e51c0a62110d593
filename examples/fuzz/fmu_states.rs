//! The FMU states of a sequence as the fuzzer keeps track of them, with the oracle's checks of
//! the functions that make, restore and free them.

use crate::fmi2::FmuState;
use crate::ops::{Arr, Blob, Slot};
use crate::view::View;

/// Serialized states kept per sequence.
const SAVED_STATES: usize = 4;

/// An FMU state of the main instance that has not been freed; `size` is
/// fmi2SerializedFMUstateSize's answer, once asked.
pub struct LiveState {
    pub ptr: FmuState,
    pub view: View,
    pub size: Option<usize>,
}

/// Bytes fmi2SerializeFMUstate wrote.
pub struct SavedState {
    pub bytes: Vec<u8>,
    view: View,
}

impl SavedState {
    /// The bytes for fmi2DeSerializeFMUstate, as they are.
    pub fn intact(&self) -> Blob {
        Blob { bytes: Arr::Items(self.bytes.clone()), how: "intact".into(), damaged: false, view: Some(self.view) }
    }
}

#[derive(Default)]
pub struct FmuStates {
    pub live: Vec<LiveState>,
    /// Freed with fmi2OK.
    pub stale: Vec<FmuState>,
    /// States of the second instance.
    pub foreign: Vec<FmuState>,
    pub saved: Vec<SavedState>,
}

impl FmuStates {
    /// The live state a function answered fmi2OK for; a violation if it is not one.
    pub fn live_mut(&mut self, state: FmuState, function: &str) -> Result<&mut LiveState, String> {
        self.live.iter_mut().find(|l| l.ptr == state).ok_or_else(|| {
            format!("{function} returned fmi2OK for {state:p}, which is NULL, freed or not a state of this instance")
        })
    }

    /// A new state from a function that answered fmi2OK.
    fn adopt(&mut self, p: FmuState, view: View, function: &str) -> Result<(), String> {
        if p.is_null() {
            return Err(format!("{function} returned fmi2OK but no state"));
        }
        if self.live.iter().any(|l| l.ptr == p) {
            return Err(format!("{function} returned the state {p:p}, which is another live state"));
        }
        self.stale.retain(|&s| s != p);
        self.live.push(LiveState { ptr: p, view, size: None });
        Ok(())
    }

    /// fmi2GetFMUstate said fmi2OK, leaving `p` in the slot; `view` is the instance's.
    pub fn got(&mut self, slot: Slot, p: FmuState, view: View) -> Result<(), String> {
        match slot {
            Slot::Null => Err("fmi2GetFMUstate returned fmi2OK for a NULL FMUstate pointer".into()),
            Slot::Holding(old) if old.is_null() => self.adopt(p, view, "fmi2GetFMUstate"),
            Slot::Holding(old) => {
                let live = self.live_mut(old, "fmi2GetFMUstate (overwriting a state)")?;
                (live.view, live.size) = (view, None);
                if p != old {
                    // The FMU may replace the state it overwrites (FMI 2.0, 2.1.8).
                    self.live.retain(|l| l.ptr != old);
                    self.stale.push(old);
                    self.adopt(p, view, "fmi2GetFMUstate")?;
                }
                Ok(())
            }
        }
    }

    /// fmi2FreeFMUstate said fmi2OK for the state `p`, leaving `after` in the slot.
    pub fn freed(&mut self, p: FmuState, after: FmuState) -> Result<(), String> {
        if !after.is_null() {
            return Err(format!("fmi2FreeFMUstate returned fmi2OK but left the pointer at {after:p}, not NULL"));
        }
        if !p.is_null() {
            self.live_mut(p, "fmi2FreeFMUstate")?;
            self.live.retain(|l| l.ptr != p);
            self.stale.push(p);
        }
        Ok(())
    }

    /// fmi2SerializeFMUstate said fmi2OK for `state`, writing `bytes`.
    pub fn serialized(&mut self, state: FmuState, bytes: Vec<u8>) -> Result<(), String> {
        let view = self.live_mut(state, "fmi2SerializeFMUstate")?.view;
        if self.saved.len() == SAVED_STATES {
            self.saved.remove(0);
        }
        self.saved.push(SavedState { bytes, view });
        Ok(())
    }

    /// fmi2DeSerializeFMUstate said fmi2OK for `blob`, making `p`.
    pub fn deserialized(&mut self, blob: &Blob, p: FmuState) -> Result<(), String> {
        if blob.damaged {
            return Err(format!("fmi2DeSerializeFMUstate returned fmi2OK for damaged bytes ({blob:?})"));
        }
        self.adopt(p, blob.view.unwrap_or_else(View::unknown), "fmi2DeSerializeFMUstate")
    }
}
