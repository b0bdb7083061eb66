//! `sahara-formats`: files in, plain arrays out.
