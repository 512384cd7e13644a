"""The core: the data a step works on and the maths it is written in (settings, exact arithmetic,
quaternions, the state and contacts arrays, argument checks, the profile). Imports no other room."""
