# clients/: the unit tests of the CLI's pure parts (tests/unit/clients)
# link the client objects they test.  Included by the top Makefile.
CLIENT_TEST_OBJ := $(BUILD)/obj/clients/batch.o $(BUILD)/obj/clients/flags.o \
                   $(BUILD)/obj/clients/bake_common.o $(BUILD)/obj/clients/cli.o

$(BUILD)/tests/clients/%: tests/unit/clients/%.c $(CLIENT_TEST_OBJ) $(PROTO_LIB) $(LIB) tests/unit/testutil.h
	@mkdir -p $(dir $@)
	$(CC) $(CPPFLAGS) $(CORE_INC) -Iclients -Iprotocol -Itests/unit $(CFLAGS) $(PKG_CFLAGS) $< -o $@ $(CLIENT_TEST_OBJ) $(PROTO_LIB) $(LIB) $(LDFLAGS) $(PKG_LIBS) -lcmocka
