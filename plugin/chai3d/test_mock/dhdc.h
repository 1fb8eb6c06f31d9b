// A minimal stand-in for the one Force Dimension SDK call the autograv bridge makes
// (dhdSetGravityCompensation, declared in the SDK's dhdc.h, which CHAI3D ships in
// externals/DHD/include). The mock records the calls so that the bridge test can check them.
#pragma once

#define DHD_ON 1
#define DHD_OFF 0

struct MockDhdState {
  int calls = 0;
  int last_value = -1;
  int last_id = -2;
  int result = 0;  // what the next call returns (0 = success, -1 = error)
};

inline MockDhdState& mockDhdState() {
  static MockDhdState state;
  return state;
}

inline int dhdSetGravityCompensation(int val = DHD_ON, char ID = -1) {
  MockDhdState& state = mockDhdState();
  ++state.calls;
  state.last_value = val;
  state.last_id = ID;
  return state.result;
}

inline const char* dhdErrorGetLastStr() { return "mock DHD error"; }
