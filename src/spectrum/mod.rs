pub mod rgb_upsample;
