//! Tests of the Mitsuba reader as a whole.
