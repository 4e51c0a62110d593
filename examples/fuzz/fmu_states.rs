//! The FMU state functions, which FMI 2.0 and FMI 3.0 declare alike but for the names
//! (fmi2GetFMUstate, fmi3GetFMUState, ...), and the FMU states of a sequence as the fuzzer keeps
//! track of them, with the oracle's checks of the functions that make, restore and free them.

use crate::fmi2::Fmi2;
use crate::fmi3::Fmi3;
use crate::ops::{Arr, Blob, Slot};
use crate::view::View;
use std::os::raw::{c_uint, c_void};
use std::ptr::null_mut;

/// An FMU state pointer (fmi2FMUstate, fmi3FMUState).
pub type FmuState = *mut c_void;
/// A status as both versions return it (fmi2Status, fmi3Status: a C enum).
pub type Status = c_uint;

/// The six FMU state functions of one version's binding, on an instance pointer.
pub trait StateFunctions {
    unsafe fn get(&self, c: *mut c_void, state: *mut FmuState) -> Status;
    unsafe fn set(&self, c: *mut c_void, state: FmuState) -> Status;
    unsafe fn free(&self, c: *mut c_void, state: *mut FmuState) -> Status;
    unsafe fn size(&self, c: *mut c_void, state: FmuState, size: *mut usize) -> Status;
    unsafe fn serialize(&self, c: *mut c_void, state: FmuState, bytes: *mut u8, size: usize) -> Status;
    unsafe fn deserialize(&self, c: *mut c_void, bytes: *const u8, size: usize, state: *mut FmuState) -> Status;
}

/// Implements `StateFunctions` for a version's binding with its six functions, in the trait's order.
macro_rules! state_functions {
    ($binding:ty: $get:ident $set:ident $free:ident $size:ident $serialize:ident $deserialize:ident) => {
        impl StateFunctions for $binding {
            unsafe fn get(&self, c: *mut c_void, state: *mut FmuState) -> Status {
                self.$get(c, state)
            }
            unsafe fn set(&self, c: *mut c_void, state: FmuState) -> Status {
                self.$set(c, state)
            }
            unsafe fn free(&self, c: *mut c_void, state: *mut FmuState) -> Status {
                self.$free(c, state)
            }
            unsafe fn size(&self, c: *mut c_void, state: FmuState, size: *mut usize) -> Status {
                self.$size(c, state, size)
            }
            unsafe fn serialize(&self, c: *mut c_void, state: FmuState, bytes: *mut u8, size: usize) -> Status {
                self.$serialize(c, state, bytes.cast(), size)
            }
            unsafe fn deserialize(
                &self,
                c: *mut c_void,
                bytes: *const u8,
                size: usize,
                state: *mut FmuState,
            ) -> Status {
                self.$deserialize(c, bytes.cast(), size, state)
            }
        }
    };
}

state_functions!(Fmi2: fmi2GetFMUstate fmi2SetFMUstate fmi2FreeFMUstate fmi2SerializedFMUstateSize
    fmi2SerializeFMUstate fmi2DeSerializeFMUstate);
state_functions!(Fmi3: fmi3GetFMUState fmi3SetFMUState fmi3FreeFMUState fmi3SerializedFMUStateSize
    fmi3SerializeFMUState fmi3DeserializeFMUState);

/// One FMU state call with its arguments (the instance is the session's, or NULL).
#[derive(Debug)]
pub enum StateCall {
    Get { state: Slot },
    Set { state: FmuState },
    Free { state: Slot },
    Size { state: FmuState, null_size: bool },
    Serialize { state: FmuState, size: usize, null_buffer: bool },
    Deserialize { bytes: Blob, null_state: bool },
}

/// What a state call wrote.
pub enum StateOutput {
    Nothing,
    /// The FMUstate variable after fmi2GetFMUstate, fmi2FreeFMUstate or fmi2DeSerializeFMUstate.
    State(FmuState),
    Size(usize),
    Bytes(Vec<u8>),
}

impl StateCall {
    /// The function's name in FMI 2.0 or (`fmi3`) FMI 3.0.
    pub fn name(&self, fmi3: bool) -> &'static str {
        let names = match self {
            StateCall::Get { .. } => ["fmi2GetFMUstate", "fmi3GetFMUState"],
            StateCall::Set { .. } => ["fmi2SetFMUstate", "fmi3SetFMUState"],
            StateCall::Free { .. } => ["fmi2FreeFMUstate", "fmi3FreeFMUState"],
            StateCall::Size { .. } => ["fmi2SerializedFMUstateSize", "fmi3SerializedFMUStateSize"],
            StateCall::Serialize { .. } => ["fmi2SerializeFMUstate", "fmi3SerializeFMUState"],
            StateCall::Deserialize { .. } => ["fmi2DeSerializeFMUstate", "fmi3DeserializeFMUState"],
        };
        names[usize::from(fmi3)]
    }

    /// The call for the trace: the function's name and the arguments.
    pub fn describe(&self, fmi3: bool) -> String {
        let all = format!("{self:?}");
        let arguments = all.find(' ').map_or("", |i| &all[i..]);
        format!("{}{arguments}", self.name(fmi3))
    }

    /// Makes the call on `c`; output buffers are temporaries of the call.
    ///
    /// # Safety
    /// `c` is NULL or an instance of `f`'s library; the arrays are as long as announced.
    pub unsafe fn invoke(&self, f: &impl StateFunctions, c: *mut c_void) -> (Status, StateOutput) {
        match self {
            StateCall::Get { state } => with_slot(*state, |p| f.get(c, p)),
            StateCall::Set { state } => (f.set(c, *state), StateOutput::Nothing),
            StateCall::Free { state } => with_slot(*state, |p| f.free(c, p)),
            StateCall::Size { state, null_size } => {
                let mut size = 0;
                let p = if *null_size { null_mut() } else { &mut size as *mut usize };
                (f.size(c, *state, p), StateOutput::Size(size))
            }
            StateCall::Serialize { state, size, null_buffer } => {
                let mut bytes = vec![0u8; if *null_buffer { 0 } else { *size }];
                let p = if *null_buffer { null_mut() } else { bytes.as_mut_ptr() };
                (f.serialize(c, *state, p, *size), StateOutput::Bytes(bytes))
            }
            StateCall::Deserialize { bytes, null_state } => {
                let (data, mut state) = (&bytes.bytes, null_mut());
                let p = if *null_state { null_mut() } else { &mut state as *mut FmuState };
                (f.deserialize(c, data.ptr(), data.len(), p), StateOutput::State(state))
            }
        }
    }
}

/// Calls `f` with the FMUstate* of a slot; the status and what the variable holds after.
unsafe fn with_slot(slot: Slot, f: impl FnOnce(*mut FmuState) -> Status) -> (Status, StateOutput) {
    let (s, held) = match slot {
        Slot::Null => (f(null_mut()), null_mut()),
        Slot::Holding(mut p) => (f(&mut p), p),
    };
    (s, StateOutput::State(held))
}

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
    /// The instance is an FMI 3.0 one (for the names in messages).
    pub fmi3: bool,
    pub live: Vec<LiveState>,
    /// Freed with fmi2OK.
    pub stale: Vec<FmuState>,
    /// States of the second instance.
    pub foreign: Vec<FmuState>,
    pub saved: Vec<SavedState>,
}

impl FmuStates {
    /// The oracle and the bookkeeping of a state call that returned OK or Warning on the main
    /// instance, whose view is `view` (restored by a set).
    pub fn observe(&mut self, call: StateCall, output: StateOutput, view: &mut View) -> Result<(), String> {
        let function = call.name(self.fmi3);
        match (call, output) {
            (StateCall::Get { state }, StateOutput::State(p)) => self.got(state, p, *view)?,
            (StateCall::Set { state }, _) => *view = self.live_mut(state, function)?.view,
            (StateCall::Free { state: Slot::Holding(p) }, StateOutput::State(after)) => self.freed(p, after)?,
            (StateCall::Size { state, .. }, StateOutput::Size(n)) => self.live_mut(state, function)?.size = Some(n),
            (StateCall::Serialize { state, .. }, StateOutput::Bytes(bytes)) => self.serialized(state, bytes)?,
            (StateCall::Deserialize { bytes, .. }, StateOutput::State(p)) => self.deserialized(&bytes, p)?,
            _ => {}
        }
        Ok(())
    }

    /// "fmi2OK" or "fmi3OK", as the messages say.
    fn ok(&self) -> &'static str {
        if self.fmi3 {
            "fmi3OK"
        } else {
            "fmi2OK"
        }
    }

    /// A function's name in this instance's version.
    fn name(&self, fmi2: &'static str, fmi3: &'static str) -> &'static str {
        if self.fmi3 {
            fmi3
        } else {
            fmi2
        }
    }

    /// The live state a function answered fmi2OK for; a violation if it is not one.
    pub fn live_mut(&mut self, state: FmuState, function: &str) -> Result<&mut LiveState, String> {
        let ok = self.ok();
        self.live.iter_mut().find(|l| l.ptr == state).ok_or_else(|| {
            format!("{function} returned {ok} for {state:p}, which is NULL, freed or not a state of this instance")
        })
    }

    /// A new state from a function that answered fmi2OK.
    fn adopt(&mut self, p: FmuState, view: View, function: &str) -> Result<(), String> {
        if p.is_null() {
            return Err(format!("{function} returned {} but no state", self.ok()));
        }
        if self.live.iter().any(|l| l.ptr == p) {
            return Err(format!("{function} returned the state {p:p}, which is another live state"));
        }
        self.stale.retain(|&s| s != p);
        self.live.push(LiveState { ptr: p, view, size: None });
        Ok(())
    }

    /// fmi2GetFMUstate said fmi2OK, leaving `p` in the slot; `view` is the instance's.
    fn got(&mut self, slot: Slot, p: FmuState, view: View) -> Result<(), String> {
        let function = self.name("fmi2GetFMUstate", "fmi3GetFMUState");
        match slot {
            Slot::Null => Err(format!("{function} returned {} for a NULL FMUstate pointer", self.ok())),
            Slot::Holding(old) if old.is_null() => self.adopt(p, view, function),
            Slot::Holding(old) => {
                let live = self.live_mut(old, &format!("{function} (overwriting a state)"))?;
                (live.view, live.size) = (view, None);
                if p != old {
                    // The FMU may replace the state it overwrites (FMI 2.0, 2.1.8).
                    self.live.retain(|l| l.ptr != old);
                    self.stale.push(old);
                    self.adopt(p, view, function)?;
                }
                Ok(())
            }
        }
    }

    /// fmi2FreeFMUstate said fmi2OK for the state `p`, leaving `after` in the slot.
    fn freed(&mut self, p: FmuState, after: FmuState) -> Result<(), String> {
        let function = self.name("fmi2FreeFMUstate", "fmi3FreeFMUState");
        if !after.is_null() {
            return Err(format!("{function} returned {} but left the pointer at {after:p}, not NULL", self.ok()));
        }
        if !p.is_null() {
            self.live_mut(p, function)?;
            self.live.retain(|l| l.ptr != p);
            self.stale.push(p);
        }
        Ok(())
    }

    /// fmi2SerializeFMUstate said fmi2OK for `state`, writing `bytes`.
    fn serialized(&mut self, state: FmuState, bytes: Vec<u8>) -> Result<(), String> {
        let view = self.live_mut(state, self.name("fmi2SerializeFMUstate", "fmi3SerializeFMUState"))?.view;
        if self.saved.len() == SAVED_STATES {
            self.saved.remove(0);
        }
        self.saved.push(SavedState { bytes, view });
        Ok(())
    }

    /// fmi2DeSerializeFMUstate said fmi2OK for `blob`, making `p`.
    fn deserialized(&mut self, blob: &Blob, p: FmuState) -> Result<(), String> {
        let function = self.name("fmi2DeSerializeFMUstate", "fmi3DeserializeFMUState");
        if blob.damaged {
            return Err(format!("{function} returned {} for damaged bytes ({blob:?})", self.ok()));
        }
        self.adopt(p, blob.view.unwrap_or_else(View::unknown), function)
    }
}
