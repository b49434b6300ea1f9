//! Integer ids for the objects of an `Index` or a `World`: insertion order,
//! never reused, each mapped to the library's generational handle.

use proxima::Handle;
use pyo3::exceptions::PyKeyError;
use pyo3::PyResult;

/// The handle of each id ever issued (`None` once removed). Ids are dense, so
/// this is a vector, 16 bytes per id.
pub struct Ids {
    handles: Vec<Option<Handle>>,
    /// What holds the objects, for messages ("index", "world").
    holder: &'static str,
    /// The handle issued last since the holder was created or cleared.
    last: Option<Handle>,
    /// Whether the live handles ascend with their ids (every handle issued
    /// since the last clear was larger than the one before). The indices break
    /// ties by handle, so while this holds their order is the ids' order;
    /// once a removed slot is reused it may not be.
    ordered: bool,
    /// Whether every id issued so far got a handle whose slot is the id
    /// itself (a fresh index filled in order; removals alone keep it, an
    /// insert into a reused slot or any insert after a clear ends it): then
    /// a handle's id is its slot, with no lookup ([`Ids::id_of_slot`]).
    slot_is_id: bool,
}

impl Ids {
    /// No id issued yet; `holder` names the container in `KeyError` messages.
    pub fn new(holder: &'static str) -> Ids {
        Ids {
            handles: Vec::new(),
            holder,
            last: None,
            ordered: true,
            slot_is_id: true,
        }
    }

    /// The handle of a live id; `KeyError` otherwise. O(1).
    pub fn handle(&self, id: i64) -> PyResult<Handle> {
        usize::try_from(id)
            .ok()
            .and_then(|i| self.handles.get(i).copied().flatten())
            .ok_or_else(|| PyKeyError::new_err(format!("id {id} is not in the {}", self.holder)))
    }

    /// Whether `id` is live.
    pub fn contains(&self, id: i64) -> bool {
        self.handle(id).is_ok()
    }

    /// The number of ids ever issued: the next id.
    pub fn issued(&self) -> usize {
        self.handles.len()
    }

    /// Issues the next id, for `h`.
    pub fn push(&mut self, h: Handle) -> i64 {
        self.ordered &= self.last.is_none_or(|last| last < h);
        self.slot_is_id &= h.index() as usize == self.handles.len();
        self.last = Some(h);
        self.handles.push(Some(h));
        (self.handles.len() - 1) as i64
    }

    /// Room for `n` more ids.
    pub fn reserve(&mut self, n: usize) {
        self.handles.reserve(n);
    }

    /// Takes back the ids issued from `first` on (undoing a failed batch) and
    /// returns their handles.
    pub fn take_from(&mut self, first: usize) -> Vec<Handle> {
        self.handles.drain(first..).flatten().collect()
    }

    /// Marks a live id removed.
    pub fn forget(&mut self, id: i64) {
        if let Some(h) = usize::try_from(id)
            .ok()
            .and_then(|i| self.handles.get_mut(i))
        {
            *h = None;
        }
    }

    /// Marks every id removed (new ids continue after the last one issued).
    pub fn forget_all(&mut self) {
        self.handles.iter_mut().for_each(|h| *h = None);
        // Nothing is live: the next handles start a new order.
        self.last = None;
        self.ordered = true;
    }

    /// Whether handle order is id order among the live ids (see the field):
    /// then a result the library ordered "ties by smaller handle" is ordered
    /// "ties by smaller id". O(1).
    pub fn ordered(&self) -> bool {
        self.ordered
    }

    /// Whether a live handle's id is its slot ([`proxima::Handle::index`]):
    /// true while every id issued got the slot of its own number (checked as
    /// each is issued, so a reused slot turns it off for good). Batch answers
    /// then name their objects without reading them back from the index, a
    /// random memory access per neighbour. O(1).
    pub fn id_of_slot(&self) -> bool {
        self.slot_is_id
    }

    /// The live ids, ascending.
    pub fn live(&self) -> Vec<i64> {
        (self.handles.iter().enumerate())
            .filter(|(_, h)| h.is_some())
            .map(|(i, _)| i as i64)
            .collect()
    }

    /// The handles of `ids`, every one live and none twice; `KeyError` naming
    /// the first that is not.
    pub fn handles_of(&self, ids: &[i64]) -> PyResult<Vec<Handle>> {
        let hs = ids
            .iter()
            .map(|&id| self.handle(id))
            .collect::<PyResult<Vec<_>>>()?;
        let mut sorted = ids.to_vec();
        sorted.sort_unstable();
        if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
            return Err(PyKeyError::new_err(format!("id {} appears twice", w[0])));
        }
        Ok(hs)
    }

    /// Heap bytes of the table.
    pub fn memory_bytes(&self) -> usize {
        self.handles.capacity() * std::mem::size_of::<Option<Handle>>()
    }
}
