//! Guards while constructing (DESIGN.md §4.8): a part made early in a constructor is destroyed
//! if a later part fails, without hand-written cleanup on every error path.

use super::Context;

/// GPU objects destroyed explicitly, with the context that made them.
pub trait Destroy {
    fn destroy(self, ctx: &Context);
}

/// Holds `item` until [`Guard::keep`]; dropped before that, it destroys the item.
pub struct Guard<'a, T: Destroy> {
    ctx: &'a Context,
    item: Option<T>,
}

impl<'a, T: Destroy> Guard<'a, T> {
    pub fn new(ctx: &'a Context, item: T) -> Self {
        Guard { ctx, item: Some(item) }
    }

    /// Construction succeeded: the item is the caller's to destroy.
    pub fn keep(mut self) -> T {
        self.item.take().expect("kept once")
    }
}

impl<T: Destroy> Drop for Guard<'_, T> {
    fn drop(&mut self) {
        if let Some(item) = self.item.take() {
            item.destroy(self.ctx);
        }
    }
}

impl Destroy for super::Pipeline {
    fn destroy(self, ctx: &Context) {
        super::Pipeline::destroy(self, ctx)
    }
}
